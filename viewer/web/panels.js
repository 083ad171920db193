// The side panels: supervisor and operator buttons, leg forces, the filter's
// active constraints, the estimator, each process's health.
'use strict';

const STATE_STATUS = ['VALID', 'INITIALIZING', 'DIVERGED', 'GROUND_TRUTH', 'PERFECT_STATE'];
const SUPERVISOR_CLASS = { DISARMED: '', ARMING: 'warn', ARMED: 'ok', HOLD: 'warn', ESTOP: 'bad' };
const HEALTH_CLASS = { OK: 'ok', DEGRADED: 'warn', FAULT: 'bad' };

function fmt(v, digits = 3) {
  return v === null || v === undefined || !Number.isFinite(v) ? '-' : v.toFixed(digits);
}

function escapeHtml(s) {
  return String(s).replace(/[&<>"]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' }[c]));
}

function statusNames(bits) {
  return STATE_STATUS.filter((_, i) => bits & (1 << i)).join(' ') || 'none';
}

class Panels {
  constructor(hello, send) {
    this.hello = hello;
    const buttons = document.getElementById('operator-buttons');
    buttons.hidden = !hello.operator;
    for (const b of buttons.querySelectorAll('button')) {
      b.onclick = () => send({ type: 'operator', command: b.dataset.command });
    }
  }

  update(frame) {
    this.supervisor(frame.supervisor, frame.operator_command);
    this.forces(frame.nominal, frame.safe);
    this.filter(frame.diagnostics);
    this.estimator(frame.estimate);
    this.health(frame.health);
  }

  supervisor(s, op) {
    const badge = document.getElementById('supervisor');
    if (!s) { badge.textContent = 'supervisor ?'; return; }
    badge.textContent = s.state_name;
    badge.className = 'badge ' + (SUPERVISOR_CLASS[s.state_name] || '');
    // The newest operator command on the bus (live only), marked when its
    // MAC does not verify: the supervisor refuses those.
    const last = op ? `<br>last operator command: ${escapeHtml(op.command)} from ` +
      `${escapeHtml(op.operator_id)} #${op.seq}${op.authentic ? '' : ' <b>(MAC does not verify)</b>'}` +
      `${op.note ? ' (' + escapeHtml(op.note) + ')' : ''}` : '';
    document.getElementById('supervisor-detail').innerHTML =
      `<b>${s.state_name}</b> ${s.state_name === 'ARMING' ? fmt(100 * s.arming_progress, 0) + ' %' : ''}` +
      ` motion ${fmt(s.motion_time_s, 2)} s${s.fault_latched ? ' <b>fault latched: reset</b>' : ''}` +
      `<br>${escapeHtml(s.reason)}${last}`;
    if (this.hello.operator && s.last_operator_id === this.hello.operator_id) {
      document.getElementById('operator-reply').textContent =
        `#${s.last_operator_seq}: ${s.last_operator_reply === '' ? 'accepted' : 'refused: ' + s.last_operator_reply}`;
    }
  }

  forces(nominal, safe) {
    let rows = '';
    for (let i = 0; i < 6; i++) {
      const fn = nominal ? nominal.force_n[i] : null, fs = safe ? safe.force_n[i] : null;
      const width = (f) => Math.min(80, Math.abs(f || 0) / 4);
      rows += `<tr><td>leg ${i}</td><td class="num">${fmt(fn, 1)}</td><td class="num">${fmt(fs, 1)}</td>` +
        `<td><span class="bar" style="width:${width(fn)}px"></span><br>` +
        `<span class="bar safe" style="width:${width(fs)}px"></span></td></tr>`;
    }
    document.getElementById('forces').innerHTML = rows;
  }

  filter(d) {
    if (!d) return;
    document.getElementById('filter').innerHTML =
      `case <b>${d.case_name}</b>, ||F* - F_des|| ${fmt(d.correction_norm_n, 2)} N, ` +
      `h_pos ${fmt(d.h_pos, 4)}, h_vel ${fmt(d.h_vel, 4)}, ${fmt(d.compute_us, 2)} us`;
    let rows = '<tr><td>barrier</td><td class="num">h</td><td class="num">LSE weight</td></tr>';
    for (const b of [...d.position, ...d.velocity]) {
      // A barrier with a weight that matters is the one the filter acts on.
      rows += `<tr class="${b.w > 0.2 ? 'active' : ''}"><td>${escapeHtml(b.name)}</td>` +
        `<td class="num">${fmt(b.h, 4)}</td><td class="num">${fmt(b.w, 3)}</td></tr>`;
    }
    document.getElementById('constraints').innerHTML = rows;
  }

  estimator(e) {
    document.getElementById('estimator').textContent = e
      ? `${statusNames(e.status)}; q = [${e.q.map((v) => fmt(v, 4)).join(', ')}]`
      : 'no state estimate';
  }

  health(list) {
    let rows = '<tr><td>process</td><td>state</td><td class="num">p99 latency</td><td class="num">missed</td></tr>';
    for (const h of list) {
      rows += `<tr><td>${escapeHtml(h.name)}</td><td><span class="badge ${HEALTH_CLASS[h.state_name] || ''}">` +
        `${h.state_name}</span>${h.fault_latched ? ' latched' : ''}</td>` +
        `<td class="num">${h.latency_p99_us === null ? '' : h.latency_p99_us + ' us'}</td>` +
        `<td class="num">${h.missed_ticks === null ? '' : h.missed_ticks}</td></tr>`;
    }
    document.getElementById('health').innerHTML = rows;
  }
}
