// Pure helpers of the page (no DOM, no three.js), so node's test runner can
// check them: number formatting, the reconnect backoff, frame decoding.

// A number with `digits` decimals, or '–' for null / non-finite (the server
// sends null for NaN and infinities: docs/viewer.md).
export function fmt(value, digits = 1, unit = '') {
  if (value === null || value === undefined || !Number.isFinite(value)) return '–';
  return value.toFixed(digits) + (unit ? ' ' + unit : '');
}

export function fmtInt(value) {
  if (value === null || value === undefined || !Number.isFinite(value)) return '–';
  return Math.round(value).toLocaleString('en-US');
}

// Reconnect delays: 250 ms doubling to a cap of 3 s.
export function backoffMs(attempt, firstMs = 250, capMs = 3000) {
  const n = Math.max(0, Math.min(attempt, 20));
  return Math.min(capMs, firstMs * 2 ** n);
}

// A bone pose [px, py, pz, qx, qy, qz, qw] is usable when all seven are numbers.
export function poseUsable(pose) {
  return Array.isArray(pose) && pose.length === 7 && pose.every((v) => typeof v === 'number' && Number.isFinite(v));
}

export function vecUsable(v, n) {
  return Array.isArray(v) && v.length === n && v.every((x) => typeof x === 'number' && Number.isFinite(x));
}

// The band's loss as a percentage of what was expected.
export function lossPercent(reports, lost) {
  if (!Number.isFinite(reports) || !Number.isFinite(lost) || reports + lost <= 0) return null;
  return (100 * lost) / (reports + lost);
}

// The ws:// URL of the viewer's socket beside the page (wss:// behind TLS).
export function socketUrl(pageHref) {
  const url = new URL('ws', pageHref);
  url.protocol = url.protocol === 'https:' ? 'wss:' : 'ws:';
  url.hash = '';
  url.search = '';
  return url.href;
}

// A stiffness level (0..1, or null) as a gauge's data-value.
export function gaugeValue(level) {
  if (level === null || level === undefined || !Number.isFinite(level)) return '';
  return Math.min(1, Math.max(0, level)).toFixed(4);
}
