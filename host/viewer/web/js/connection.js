// The page's WebSocket to tonusd (docs/viewer.md): reconnects with a backoff
// (250 ms doubling, capped at 3 s), matches replies to requests by id, and
// hands scene, frame and error messages to its listeners.
import { backoffMs } from './format.js';

const REQUEST_TIMEOUT_MS = 5000;
const MAX_PENDING = 64; // requests awaiting a reply; more are refused at once

export class Connection {
  constructor(url, { onScene, onFrame, onError, onState }) {
    this.url = url;
    this.handlers = { onScene, onFrame, onError, onState };
    this.socket = null;
    this.connected = false;
    this.attempt = 0;
    this.nextId = 1;
    this.pending = new Map(); // id -> {resolve, reject, timer}
    this.retryTimer = null;
    this.retryAt = 0;
    this.closedByUs = false;
  }

  start() {
    this.closedByUs = false;
    this.open();
  }

  stop() {
    this.closedByUs = true;
    clearTimeout(this.retryTimer);
    if (this.socket) this.socket.close(1000, 'page closed');
  }

  open() {
    clearTimeout(this.retryTimer);
    let socket;
    try {
      socket = new WebSocket(this.url);
    } catch (error) {
      this.scheduleRetry(String(error));
      return;
    }
    this.socket = socket;
    this.setState('connecting');
    socket.addEventListener('open', () => {
      this.connected = true;
      this.attempt = 0;
      this.setState('open');
    });
    socket.addEventListener('message', (event) => this.receive(event.data));
    socket.addEventListener('close', (event) => {
      if (this.socket !== socket) return;
      this.socket = null;
      const was = this.connected;
      this.connected = false;
      this.failPending('the connection to tonusd closed');
      if (this.closedByUs) {
        this.setState('closed');
        return;
      }
      this.scheduleRetry(was ? `closed (${event.code}${event.reason ? ': ' + event.reason : ''})` : 'not reachable');
    });
    // 'error' is always followed by 'close', which does the work.
  }

  scheduleRetry(reason) {
    const delay = backoffMs(this.attempt++);
    this.retryAt = Date.now() + delay;
    this.setState('retrying', { reason, delay });
    this.retryTimer = setTimeout(() => this.open(), delay);
  }

  setState(state, detail = {}) {
    if (this.handlers.onState) this.handlers.onState(state, detail);
  }

  receive(text) {
    let message;
    try {
      message = JSON.parse(text);
    } catch {
      return; // the server only sends JSON
    }
    switch (message.type) {
      case 'scene':
        this.handlers.onScene?.(message);
        break;
      case 'frame':
        this.handlers.onFrame?.(message);
        break;
      case 'reply': {
        const waiting = this.pending.get(message.id);
        if (waiting) {
          this.pending.delete(message.id);
          clearTimeout(waiting.timer);
          waiting.resolve({ status: message.status, body: message.body });
        }
        break;
      }
      case 'error': {
        const waiting = message.id !== undefined ? this.pending.get(message.id) : undefined;
        if (waiting) {
          this.pending.delete(message.id);
          clearTimeout(waiting.timer);
          waiting.reject(new Error(message.error));
        } else {
          this.handlers.onError?.(message.error);
        }
        break;
      }
      default:
        break;
    }
  }

  send(message) {
    if (!this.socket || !this.connected) throw new Error('not connected to tonusd');
    this.socket.send(JSON.stringify(message));
  }

  // A control API call (docs/control.md): resolves to {status, body}.
  request(method, path, body) {
    return new Promise((resolve, reject) => {
      if (this.pending.size >= MAX_PENDING) {
        reject(new Error('too many requests waiting for tonusd'));
        return;
      }
      const id = this.nextId++;
      try {
        const message = { type: 'request', id, method, path };
        if (body !== undefined) message.body = body;
        this.send(message);
      } catch (error) {
        reject(error);
        return;
      }
      const timer = setTimeout(() => {
        this.pending.delete(id);
        reject(new Error(`no reply to ${method} ${path} within ${REQUEST_TIMEOUT_MS / 1000} s`));
      }, REQUEST_TIMEOUT_MS);
      this.pending.set(id, { resolve, reject, timer });
    });
  }

  playback(action, positionS) {
    const message = { type: 'playback', action };
    if (action === 'seek') message.position_s = positionS;
    this.send(message);
  }

  failPending(reason) {
    for (const [, waiting] of this.pending) {
      clearTimeout(waiting.timer);
      waiting.reject(new Error(reason));
    }
    this.pending.clear();
  }
}
