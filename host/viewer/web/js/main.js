// The viewer page: connects to tonusd's WebSocket, draws each frame, and
// sends the controls as control API requests (docs/viewer.md). Test hooks:
// window.tonusViewer (read-only state) and data-value on the gauges.
import { Connection } from './connection.js';
import { socketUrl } from './format.js';
import { Panel } from './panel.js';
import { View3D } from './scene3d.js';

const $ = (id) => document.getElementById(id);

export function startViewer() {
  const panel = new Panel();
  let view = null;
  try {
    view = new View3D($('view'));
  } catch (error) {
    // three.js loaded but WebGL did not start: the panel still works.
    const box = $('fatal');
    box.textContent = `the 3D view is not available (${error && error.message ? error.message : error}); ` +
      'status and controls still work';
    box.hidden = false;
  }

  const state = {
    connected: false,
    scene: null,
    lastFrame: null,   // the newest frame received (also while the view is paused)
    shownFrame: null,  // the frame the view and panel show
    pending: null,     // received, not yet drawn
    framesReceived: 0,
    framesShown: 0,
    sceneBuilds: 0,
    paused: false,
    lastReply: null,
    lastError: null,
    requests: 0,
  };

  function applyScene(scene) {
    state.scene = scene;
    state.sceneBuilds++;
    panel.setScene(scene);
    if (view) view.setScene(scene);
    panel.setControlsEnabled(state.connected);
    state.pending = state.lastFrame;
  }

  const connection = new Connection(socketUrl(location.href), {
    onScene: applyScene,
    onFrame(frame) {
      state.framesReceived++;
      state.lastFrame = frame;
      panel.countFrame();
      if (!state.paused) state.pending = frame;
    },
    onError(message) {
      state.lastError = message;
      panel.status(`tonusd: ${message}`, 'bad');
    },
    onState(s, detail) {
      state.connected = s === 'open';
      panel.setConnection(s, detail);
      panel.setControlsEnabled(state.connected && state.scene !== null);
    },
  });

  // Drawing: the newest frame once per animation frame.
  function animate() {
    if (state.pending && state.scene) {
      const frame = state.pending;
      state.pending = null;
      if (view) view.setFrame(frame);
      panel.setFrame(frame, { paused: state.paused });
      state.shownFrame = frame;
      state.framesShown++;
    }
    if (view) view.render();
    requestAnimationFrame(animate);
  }
  requestAnimationFrame(animate);

  // ---- controls: every one is a control API request (docs/control.md) ----

  async function call(label, method, path, body) {
    state.requests++;
    panel.status(`${label}…`);
    try {
      const reply = await connection.request(method, path, body);
      state.lastReply = { method, path, status: reply.status, body: reply.body };
      const ok = reply.status >= 200 && reply.status < 300;
      const detail = ok ? JSON.stringify(reply.body) : reply.body?.error ?? JSON.stringify(reply.body);
      panel.status(`${label}: ${reply.status} ${detail}`, ok ? 'good' : 'bad');
      return reply;
    } catch (error) {
      state.lastReply = { method, path, status: 0, error: error.message };
      panel.status(`${label}: ${error.message}`, 'bad');
      return null;
    }
  }

  $('throw-ball').addEventListener('click', () => {
    const bone = $('gift-bone').value;
    call(`throw a ball at ${bone}`, 'POST', '/gifts', { kind: 'ball', bone });
  });
  $('drop-cube').addEventListener('click', () => {
    const bone = $('gift-bone').value;
    call(`drop a cube on ${bone}`, 'POST', '/gifts', { kind: 'cube', bone });
  });
  $('clear-gifts').addEventListener('click', () => call('clear the gifts', 'DELETE', '/gifts'));

  const slider = $('stiffness-slider');
  const levels = () => {
    const n = state.scene && Array.isArray(state.scene.groups) && state.scene.groups.length ? state.scene.groups.length : 4;
    return Array(n).fill(Number(slider.value));
  };
  slider.addEventListener('input', () => {
    $('stiffness-slider-value').textContent = Number(slider.value).toFixed(2);
  });
  // Dragging the slider overrides live, at most ten requests a second.
  let overrideTimer = null;
  slider.addEventListener('input', () => {
    if (overrideTimer) return;
    overrideTimer = setTimeout(() => {
      overrideTimer = null;
      call(`override stiffness ${Number(slider.value).toFixed(2)}`, 'PUT', '/stiffness', { levels: levels() });
    }, 100);
  });
  $('stiffness-apply').addEventListener('click', () =>
    call(`override stiffness ${Number(slider.value).toFixed(2)}`, 'PUT', '/stiffness', { levels: levels() }));
  $('stiffness-release').addEventListener('click', () =>
    call('release the override', 'PUT', '/stiffness', { levels: null }));

  $('pause-view').addEventListener('click', () => {
    state.paused = !state.paused;
    const button = $('pause-view');
    button.setAttribute('aria-pressed', String(state.paused));
    button.textContent = state.paused ? 'resume view' : 'pause view';
    $('hud-paused').hidden = !state.paused;
    // Paused: nothing more is drawn, not even a frame that arrived just before.
    state.pending = state.paused ? null : state.lastFrame;
  });
  $('reset-camera').addEventListener('click', () => view?.resetCamera());
  $('show-ghost').addEventListener('change', (e) => {
    if (view) view.showGhost = e.target.checked;
    state.pending = state.shownFrame;
  });
  $('show-contacts').addEventListener('change', (e) => {
    if (view) view.showContacts = e.target.checked;
    state.pending = state.shownFrame;
  });

  // The VRM avatar (when the scene names one): its status line and its and
  // the capsules' checkboxes. Once it loads the capsules step aside, unless
  // the user chose; when it fails they are back, whatever was chosen.
  let capsulesChosen = false;
  const setCapsules = (shown) => {
    $('show-capsules').checked = shown;
    if (view) view.showCapsules = shown;
    state.pending = state.shownFrame;
  };
  $('show-capsules').addEventListener('change', (e) => {
    capsulesChosen = true;
    setCapsules(e.target.checked);
  });
  $('show-vrm').addEventListener('change', (e) => {
    if (view) view.vrm.setVisible(e.target.checked);
    state.pending = state.shownFrame;
  });
  if (view) {
    view.onVrmChange = (avatar) => {
      const line = $('vrm-status');
      line.hidden = avatar.state === 'none';
      line.dataset.state = avatar.state;
      line.textContent = avatar.state === 'failed' ? `VRM avatar: ${avatar.message}; showing the capsules` :
        `VRM avatar: ${avatar.message}`;
      line.className = `status ${avatar.state === 'failed' ? 'bad' : avatar.state === 'loaded' ? 'good' : ''}`;
      $('vrm-toggle').hidden = avatar.state !== 'loaded';
      if (avatar.state === 'loaded' && !capsulesChosen) setCapsules(false);
      if (avatar.state === 'failed' || avatar.state === 'none') setCapsules(true);
      if (avatar.state === 'loaded') view.vrm.setVisible($('show-vrm').checked);
      state.pending = state.shownFrame;
    };
  }

  // Timeline (only shown while frames carry "playback").
  const seek = $('seek');
  seek.addEventListener('pointerdown', () => { panel.seeking = true; });
  seek.addEventListener('change', () => {
    panel.seeking = false;
    try {
      connection.playback('seek', Number(seek.value));
    } catch (error) {
      panel.status(error.message, 'bad');
    }
  });
  $('play-toggle').addEventListener('click', () => {
    const playing = $('play-toggle').dataset.playing === 'true';
    try {
      connection.playback(playing ? 'pause' : 'play');
    } catch (error) {
      panel.status(error.message, 'bad');
    }
  });

  // Test hooks (read-only views of the state).
  window.tonusViewer = {
    get connected() { return state.connected; },
    get framesReceived() { return state.framesReceived; },
    get framesShown() { return state.framesShown; },
    get lastFrame() { return state.lastFrame; },
    get shownFrame() { return state.shownFrame; },
    get scene() { return state.scene; },
    get sceneBuilds() { return state.sceneBuilds; },
    get paused() { return state.paused; },
    get objectsShown() { return view ? view.objectCount : 0; },
    get webgl() { return view !== null; },
    get lastReply() { return state.lastReply; },
    get lastError() { return state.lastError; },
    get capsulesShown() { return view ? view.showCapsules : false; },
    // The VRM avatar: state ('none', 'loading', 'loaded', 'failed'), its
    // message, and what was driven (the frame's tick, the normalized local
    // rotations and hips position set; the model's bones as drawn).
    get vrm() {
      const avatar = view ? view.vrm : null;
      return {
        state: avatar ? avatar.state : 'none',
        message: avatar ? avatar.message : '',
        version: avatar ? avatar.version : null,
        visible: avatar ? avatar.visible && avatar.state === 'loaded' : false,
        applied: avatar && avatar.applied ? structuredClone(avatar.applied) : null,
        normalizedLocal: (name) => (avatar ? avatar.normalizedLocal(name) : null),
        rawWorldPosition: (name) => (avatar ? avatar.rawWorldPosition(name) : null),
      };
    },
  };

  connection.start();
}
