// Keeps one headless Chromium on the viewer's page for a while (the cost
// measurement's browser, tools/viewer_cost.sh): node watch.js URL SECONDS.
// Prints the frames the page received and rendered.
'use strict';

const puppeteer = require('puppeteer-core');

const [url, seconds] = process.argv.slice(2);

(async () => {
  const browser = await puppeteer.launch({
    executablePath: process.env.STEWART_CHROMIUM || '/usr/bin/chromium',
    headless: true,
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--window-size=1280,800'],
  });
  try {
    const page = await browser.newPage();
    await page.setViewport({ width: 1280, height: 800 });
    await page.goto(url, { waitUntil: 'load', timeout: 20000 });
    await new Promise((resolve) => setTimeout(resolve, Number(seconds) * 1000));
    const s = await page.evaluate(() => window.viewerState);
    console.log(`watch: ${s.frames} frames received, ${s.renderedFrames} rendered in ${seconds} s`);
  } finally {
    await browser.close();
  }
})().catch((e) => {
  console.error(`watch: ${e.message}`);
  process.exit(1);
});
