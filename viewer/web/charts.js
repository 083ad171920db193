// Strip charts of the last history_s seconds of stack time, on plain canvas.
// Samples come from the frames (live) or, after a seek, from the log's history.
'use strict';

class StripChart {
  // series: [{label, colour, value(sample)}]; limits: [{value, colour}]
  constructor(canvas, title, series) {
    this.canvas = canvas;
    this.title = title;
    this.series = series;
    this.limits = [];
  }

  draw(samples, historyS) {
    const c = this.canvas;
    // Match the canvas's pixels to its laid-out size.
    if (c.width !== c.clientWidth && c.clientWidth > 0) c.width = c.clientWidth;
    const g = c.getContext('2d');
    g.clearRect(0, 0, c.width, c.height);
    g.fillStyle = '#9ab';
    g.font = '11px sans-serif';
    g.fillText(this.title, 4, 12);
    if (samples.length === 0) return;
    const tEnd = samples[samples.length - 1].t;
    const tStart = tEnd - historyS;
    let lo = Infinity, hi = -Infinity;
    for (const s of samples) {
      for (const ser of this.series) {
        const v = ser.value(s);
        if (Number.isFinite(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
      }
    }
    for (const l of this.limits) { lo = Math.min(lo, l.value); hi = Math.max(hi, l.value); }
    if (!(hi > lo)) { hi = lo + 1e-3; lo -= 1e-3; }
    const pad = 0.08 * (hi - lo);
    lo -= pad; hi += pad;
    const x = (t) => ((t - tStart) / historyS) * (c.width - 50) + 45;
    const y = (v) => c.height - 4 - ((v - lo) / (hi - lo)) * (c.height - 20);
    g.fillText(hi.toPrecision(3), 2, 26);
    g.fillText(lo.toPrecision(3), 2, c.height - 6);
    g.setLineDash([4, 3]);
    for (const l of this.limits) {
      g.strokeStyle = l.colour;
      g.beginPath(); g.moveTo(45, y(l.value)); g.lineTo(c.width, y(l.value)); g.stroke();
    }
    g.setLineDash([]);
    this.series.forEach((ser, k) => {
      g.strokeStyle = ser.colour;
      g.beginPath();
      let started = false;
      for (const s of samples) {
        const v = ser.value(s);
        if (!Number.isFinite(v) || s.t < tStart) continue;
        if (started) g.lineTo(x(s.t), y(v)); else { g.moveTo(x(s.t), y(v)); started = true; }
      }
      g.stroke();
      g.fillStyle = ser.colour;
      g.fillText(ser.label, 170 + 30 * k, 12);  // right of the title
    });
  }
}

// The samples of the last historyS seconds; cleared when time goes back (a seek).
class History {
  constructor() { this.samples = []; this.historyS = 10; }
  add(sample) {
    const last = this.samples[this.samples.length - 1];
    if (last && sample.t < last.t) this.samples = [];
    if (last && sample.t === last.t) return;
    this.samples.push(sample);
    const from = sample.t - this.historyS;
    let drop = 0;
    while (drop < this.samples.length && this.samples[drop].t < from) drop++;
    if (drop > 0) this.samples.splice(0, drop);
  }
  replace(samples) { this.samples = samples; }
}
