// The side panel: stiffness gauges, band, tick metrics, tracker state, the
// heads-up line and the playback timeline. DOM only (no three.js).
import { fmt, fmtInt, gaugeValue, lossPercent } from './format.js';

const $ = (id) => document.getElementById(id);

function setText(id, text) {
  const el = $(id);
  if (el.textContent !== text) el.textContent = text;
}

function yesNo(value, yes = 'yes', no = 'no') {
  if (value === true) return yes;
  if (value === false) return no;
  return '–';
}

export class Panel {
  constructor() {
    this.gauges = [];
    this.seeking = false; // the user holds the seek slider
    this.lastFpsAt = performance.now();
    this.framesSinceFps = 0;
  }

  setScene(scene) {
    const box = $('gauges');
    box.replaceChildren();
    this.gauges = [];
    const groups = Array.isArray(scene.groups) ? scene.groups : [];
    for (const [i, name] of groups.entries()) {
      const row = document.createElement('div');
      row.className = 'gauge';
      row.dataset.group = name;
      row.dataset.index = String(i);
      row.dataset.value = '';
      row.setAttribute('role', 'meter');
      row.setAttribute('aria-label', `${name} stiffness`);
      row.setAttribute('aria-valuemin', '0');
      row.setAttribute('aria-valuemax', '1');
      const label = document.createElement('span');
      label.className = 'name';
      label.textContent = name.replace(/_/g, ' ');
      label.title = name;
      const bar = document.createElement('span');
      bar.className = 'bar';
      const fill = document.createElement('span');
      fill.className = 'fill';
      fill.style.display = 'block';
      bar.appendChild(fill);
      const value = document.createElement('span');
      value.className = 'value';
      value.textContent = '–';
      row.append(label, bar, value);
      box.appendChild(row);
      this.gauges.push({ row, fill, value });
    }
    if (groups.length === 0) box.innerHTML = '<p class="muted">no stiffness groups</p>';

    const picker = $('gift-bone');
    const previous = picker.value;
    picker.replaceChildren();
    const bones = Array.isArray(scene.gift_bones) ? scene.gift_bones : [];
    for (const bone of bones) {
      const option = document.createElement('option');
      option.value = bone;
      option.textContent = bone;
      picker.appendChild(option);
    }
    if (bones.includes(previous)) picker.value = previous;
    else if (bones.includes('Chest')) picker.value = 'Chest';

    const mode = $('mode');
    mode.textContent = scene.mode || '';
    mode.hidden = !scene.mode;
  }

  setFrame(frame, { paused }) {
    const stiffness = Array.isArray(frame.stiffness) ? frame.stiffness : [];
    for (const [i, g] of this.gauges.entries()) {
      const v = gaugeValue(stiffness[i]);
      if (g.row.dataset.value === v) continue;
      g.row.dataset.value = v;
      g.row.setAttribute('aria-valuenow', v);
      g.fill.style.width = v === '' ? '0%' : `${(100 * Number(v)).toFixed(1)}%`;
      g.value.textContent = v === '' ? '–' : Number(v).toFixed(2);
    }

    setText('hud-time', `t = ${fmt(frame.time_s, 2, 's')}`);
    setText('hud-tick', `tick ${fmtInt(frame.tick)}`);
    $('hud-override').hidden = !frame.override_active;
    $('hud-paused').hidden = !paused;

    const band = frame.band ?? {};
    setText('band-source', band.source || '–');
    const link = band.connected === true ? (band.live ? 'connected, live' : 'connected, stale') : yesNo(band.connected, 'connected', 'not connected');
    setText('band-link', link);
    $('band-link').className = band.connected && band.live ? 'good' : 'bad';
    setText('band-calibrated', yesNo(band.calibrated));
    setText('band-latency', `${fmt(band.latency_p50_ms, 1)} / ${fmt(band.latency_p99_ms, 1)} ms (p50 / p99)`);
    setText('band-reports', fmtInt(band.reports));
    const loss = lossPercent(band.reports, band.lost);
    setText('band-loss', `${fmtInt(band.lost)} (${fmt(loss, 2, '%')})`);

    const m = frame.metrics ?? {};
    setText('tracker-state', frame.tracker_state || '–');
    setText('tracker-rate', fmt(m.tracker_rate_hz, 0, 'Hz'));
    setText('metric-ticks', fmtInt(m.ticks));
    setText('metric-tick', `${fmt(m.tick_p50_us, 0)} / ${fmt(m.tick_p99_us, 0)} µs`);
    setText('metric-tick-max', fmt(m.tick_max_us, 0, 'µs'));
    setText('metric-overruns', fmtInt(m.overruns));

    this.setPlayback(frame.playback);
  }

  setPlayback(playback) {
    const timeline = $('timeline');
    if (!playback || typeof playback !== 'object') {
      timeline.hidden = true;
      return;
    }
    timeline.hidden = false;
    const seek = $('seek');
    const duration = Number.isFinite(playback.duration_s) ? playback.duration_s : 0;
    if (Number(seek.max) !== duration) seek.max = String(duration);
    if (!this.seeking && Number.isFinite(playback.position_s)) seek.value = String(playback.position_s);
    setText('playback-time', `${fmt(playback.position_s, 1)} / ${fmt(duration, 1)} s`);
    const toggle = $('play-toggle');
    toggle.dataset.playing = playback.playing ? 'true' : 'false';
    setText('play-toggle', playback.playing ? 'pause' : 'play');
  }

  // Frames received per second, for the heads-up line.
  countFrame() {
    this.framesSinceFps++;
    const now = performance.now();
    if (now - this.lastFpsAt >= 1000) {
      setText('hud-fps', `${((1000 * this.framesSinceFps) / (now - this.lastFpsAt)).toFixed(0)} frames/s`);
      this.framesSinceFps = 0;
      this.lastFpsAt = now;
    }
  }

  // Connection badge and overlay.
  setConnection(state, detail) {
    const badge = $('conn-state');
    const overlay = $('overlay');
    badge.dataset.state = state;
    if (state === 'open') {
      badge.textContent = 'connected';
      badge.className = 'badge good';
      overlay.dataset.visible = 'false';
      return;
    }
    badge.className = 'badge bad';
    if (state === 'retrying') {
      badge.textContent = 'not connected';
      overlay.dataset.visible = 'true';
      setText('overlay-title', 'tonusd is not reachable, retrying…');
      const seconds = (detail.delay / 1000).toFixed(1);
      setText('overlay-detail', `${detail.reason}; next try in ${seconds} s. Is tonusd running?`);
    } else if (state === 'connecting') {
      badge.textContent = 'connecting…';
    } else {
      badge.textContent = state;
    }
  }

  setControlsEnabled(enabled) {
    for (const id of ['gift-bone', 'throw-ball', 'drop-cube', 'clear-gifts', 'stiffness-slider', 'stiffness-apply',
      'stiffness-release']) {
      $(id).disabled = !enabled;
    }
  }

  status(text, kind = '') {
    const el = $('request-status');
    el.textContent = text;
    el.className = `status ${kind}`;
  }
}
