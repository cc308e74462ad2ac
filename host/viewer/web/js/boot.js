// Starts the viewer. A module that imports nothing itself, so it runs even
// when three.js is missing (the import map then points at 404s), and says
// so on the page instead of leaving it blank.
const THREE_MISSING = 'three.js is not installed: run scripts/install-deps.sh';

function showFatal(message, detail) {
  const box = document.getElementById('fatal');
  box.textContent = message;
  if (detail) {
    const small = document.createElement('div');
    small.className = 'muted';
    small.textContent = detail;
    box.appendChild(small);
  }
  box.hidden = false;
  document.documentElement.dataset.viewerError = message;
}

async function threeInstalled() {
  try {
    const reply = await fetch(new URL('../vendor/three/three.module.js', import.meta.url), { method: 'HEAD' });
    return reply.ok;
  } catch {
    return true; // the server is not reachable: that is another story (main.js tells it)
  }
}

try {
  const { startViewer } = await import('./main.js');
  startViewer();
} catch (error) {
  if (!(await threeInstalled())) {
    showFatal(THREE_MISSING, 'tonusd serves three.js from host/viewer/web/node_modules (npm ci there).');
  } else {
    showFatal('the viewer failed to start', String(error && error.stack ? error.stack : error));
  }
  // The overlay would hide the message: it is about the daemon, not this.
  document.getElementById('overlay').dataset.visible = 'false';
  const badge = document.getElementById('conn-state');
  badge.textContent = 'not started';
  badge.dataset.state = 'failed';
  window.tonusViewer = { connected: false, framesReceived: 0, error: document.documentElement.dataset.viewerError };
}
