// The page's pure helpers (host/viewer/web/js/format.js) under node's test runner.
import test from 'node:test';
import assert from 'node:assert/strict';
import {
  backoffMs, fmt, fmtInt, gaugeValue, lossPercent, poseUsable, socketUrl, vecUsable,
} from '../../host/viewer/web/js/format.js';

test('numbers: null and non-finite show as a dash', () => {
  assert.equal(fmt(1.234, 2), '1.23');
  assert.equal(fmt(2, 1, 'ms'), '2.0 ms');
  assert.equal(fmt(null), '–');
  assert.equal(fmt(undefined), '–');
  assert.equal(fmt(Number.NaN), '–');
  assert.equal(fmtInt(12345.6), '12,346');
  assert.equal(fmtInt(null), '–');
});

test('reconnect backoff doubles from 250 ms and is capped at 3 s', () => {
  assert.deepEqual([0, 1, 2, 3, 4, 5, 50].map((n) => backoffMs(n)), [250, 500, 1000, 2000, 3000, 3000, 3000]);
});

test('a pose is usable only as seven finite numbers (the server sends null for NaN)', () => {
  assert.ok(poseUsable([0, 0, 1, 0, 0, 0, 1]));
  assert.ok(!poseUsable([0, 0, null, 0, 0, 0, 1]));
  assert.ok(!poseUsable([0, 0, 1, 0, 0, 0]));
  assert.ok(!poseUsable(null));
  assert.ok(vecUsable([1, 2], 2));
  assert.ok(!vecUsable([1, null], 2));
});

test('gauge values: four decimals, clamped to 0..1, empty when unknown', () => {
  assert.equal(gaugeValue(0.5), '0.5000');
  assert.equal(gaugeValue(1.2), '1.0000');
  assert.equal(gaugeValue(-0.1), '0.0000');
  assert.equal(gaugeValue(null), '');
  assert.equal(gaugeValue(Number.NaN), '');
});

test('band loss as a percentage of what was expected', () => {
  assert.equal(lossPercent(99, 1), 1);
  assert.equal(lossPercent(0, 0), null);
  assert.equal(lossPercent(null, 1), null);
});

test('the socket sits beside the page: ws://HOST/ws, wss:// behind TLS', () => {
  assert.equal(socketUrl('http://127.0.0.1:39546/'), 'ws://127.0.0.1:39546/ws');
  assert.equal(socketUrl('http://127.0.0.1:39546/index.html?x=1#top'), 'ws://127.0.0.1:39546/ws');
  assert.equal(socketUrl('https://example.org/tonus/'), 'wss://example.org/tonus/ws');
});
