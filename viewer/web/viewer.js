// The page's main: the WebSocket to stewart_viewer, the render loop, the
// playback bar. window.viewerState exposes what the last rendered frame
// showed (the browser test reads it).
'use strict';

window.viewerState = { connected: false, frames: 0, renderedFrames: 0, mode: null, operator: null,
                       utime_us: null, t_s: null, q: null, setpoint: null, playback: null, errors: [] };

(function main() {
  const scene = new PlatformScene(document.getElementById('view'));
  const history = new History();
  let panels = null;
  let latest = null;     // newest frame received, not yet drawn
  let socket = null;

  const colours = ['#e57373', '#81c784', '#64b5f6'];
  const axes = ['x', 'y', 'z'];
  const chartQ = new StripChart(document.getElementById('chart-q'), 'q (m) and limits',
    axes.map((a, i) => ({ label: a, colour: colours[i], value: (s) => s.q[i] })));
  const chartQd = new StripChart(document.getElementById('chart-qd'), 'qd (m/s) and limits',
    axes.map((a, i) => ({ label: a, colour: colours[i], value: (s) => s.qd[i] })));
  const chartCorrection = new StripChart(document.getElementById('chart-correction'),
    '||F* - F_des|| (N)', [{ label: 'norm', colour: '#ffb74d', value: (s) => s.correction }]);

  function send(message) {
    if (socket && socket.readyState === WebSocket.OPEN) socket.send(JSON.stringify(message));
  }

  function showMessage(text) {
    document.getElementById('message').textContent = text;
  }

  function limitLines(limits) {
    const lines = [];
    for (const l of limits) {
      if (l.axis > 2) continue;
      for (const v of [l.lower, l.upper]) if (v !== null) lines.push({ value: v, colour: colours[l.axis] });
    }
    return lines;
  }

  function onHello(hello) {
    scene.build(hello);
    panels = new Panels(hello, send);
    history.historyS = hello.history_s;
    chartQ.limits = limitLines(hello.limits.position);
    chartQd.limits = limitLines(hello.limits.velocity);
    window.viewerState.mode = hello.mode;
    window.viewerState.operator = hello.operator;
    const mode = document.getElementById('mode');
    mode.textContent = hello.mode === 'log' ? 'LOG' : 'LIVE';
    const access = document.getElementById('access');
    access.textContent = hello.mode === 'log' ? 'recorded' : hello.operator ? 'OPERATOR' : 'read-only';
    access.className = 'badge ' + (hello.operator ? 'warn' : '');
    if (hello.mode === 'log') setUpPlayback(hello.log);
  }

  function setUpPlayback(log) {
    document.getElementById('playback').hidden = false;
    const slider = document.getElementById('slider');
    slider.min = log.start_s;
    slider.max = log.end_s;
    slider.step = 0.001;
    slider.addEventListener('input', () => send({ type: 'seek', t_s: Number(slider.value) }));
    const play = document.getElementById('play');
    play.onclick = () => send({ type: play.textContent === 'play' ? 'play' : 'pause' });
    document.getElementById('rate').onchange = (e) => send({ type: 'rate', rate: Number(e.target.value) });
  }

  function onFrame(frame) {
    window.viewerState.frames++;
    if (frame.history) {
      const h = frame.history;
      history.replace(h.t_s.map((t, k) => ({ t, q: h.q[k], qd: h.qd[k], correction: h.correction_norm_n[k] })));
    }
    if (frame.estimate) {
      history.add({ t: frame.t_s, q: frame.estimate.q, qd: frame.estimate.qd,
                    correction: frame.diagnostics ? frame.diagnostics.correction_norm_n : NaN });
    }
    latest = frame;
  }

  // Draws the newest frame once per display refresh; frames that arrive in
  // between only replace it.
  function draw(frame) {
    scene.update(frame);
    panels.update(frame);
    document.getElementById('clock').textContent = `t = ${frame.t_s.toFixed(3)} s`;
    if (frame.playback) {
      const pb = frame.playback;
      const slider = document.getElementById('slider');
      if (document.activeElement !== slider) slider.value = pb.t_s;
      document.getElementById('slider-time').textContent = `${pb.t_s.toFixed(2)} / ${pb.end_s.toFixed(2)} s`;
      document.getElementById('play').textContent = pb.playing ? 'pause' : 'play';
    }
    chartQ.draw(history.samples, history.historyS);
    chartQd.draw(history.samples, history.historyS);
    chartCorrection.draw(history.samples, history.historyS);
    const s = window.viewerState;
    s.renderedFrames++;
    s.utime_us = frame.estimate ? frame.estimate.utime_us : null;
    s.t_s = frame.t_s;
    s.q = frame.estimate ? frame.estimate.q.slice() : null;
    s.truth_q = frame.truth ? frame.truth.q.slice() : null;
    s.setpoint = frame.setpoint ? frame.setpoint.slice() : null;
    s.supervisor = frame.supervisor ? frame.supervisor.state_name : null;
    s.playback = frame.playback || null;
  }

  // Renders only when there is something new to show (a frame, or the
  // camera moved): an idle page costs its machine nothing.
  let cameraMoved = true;
  scene.controls.addEventListener('change', () => { cameraMoved = true; });
  window.addEventListener('resize', () => { cameraMoved = true; });
  function animate() {
    requestAnimationFrame(animate);
    const fresh = latest && panels;
    if (fresh) {
      draw(latest);
      latest = null;
    }
    if (fresh || cameraMoved) {
      cameraMoved = false;
      scene.render();
    }
  }

  function connect() {
    socket = new WebSocket(`ws://${location.host}/ws`);
    socket.onopen = () => { window.viewerState.connected = true; showMessage(''); };
    socket.onclose = () => {
      window.viewerState.connected = false;
      showMessage('disconnected from stewart_viewer: retrying');
      setTimeout(connect, 1000);
    };
    socket.onmessage = (event) => {
      const msg = JSON.parse(event.data);
      if (msg.type === 'hello') onHello(msg);
      else if (msg.type === 'frame') onFrame(msg);
      else if (msg.type === 'error') {
        window.viewerState.errors.push(msg.message);
        showMessage(msg.message);
      }
    };
  }

  connect();
  animate();
})();
