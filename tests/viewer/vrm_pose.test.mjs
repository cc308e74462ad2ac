// The VRM avatar's pose math (host/viewer/web/js/vrm_pose.js) under node's
// test runner: bone names, frames, and what a rotation of tonus's bone does
// to the model's bone, checked by where it sends the bone's direction.
import test from 'node:test';
import assert from 'node:assert/strict';
import { makeRig, qmul, qconj, rootScale, vrmBoneName, vrmPose } from '../../host/viewer/web/js/vrm_pose.js';

// v rotated by q ([x, y, z, w]).
function rotate(q, v) {
  const r = qmul(qmul(q, [v[0], v[1], v[2], 0]), qconj(q));
  return r.slice(0, 3);
}
const about = (axis, angle) => [...axis.map((c) => c * Math.sin(angle / 2)), Math.cos(angle / 2)];
const close = (a, b, eps = 1e-9) => a.every((x, i) => Math.abs(x - b[i]) < eps);
const I = [0, 0, 0, 1];

// A small tonus-like scene: Hips <- Spine <- Chest <- Neck; Chest <- LeftShoulder <- LeftUpperArm.
function scene() {
  const bone = (name, parent, pos) => ({ name, parent, group: -1, rest: [...pos, 0, 0, 0, 1] });
  return {
    ground_z_m: 0,
    bones: [
      bone('Hips', -1, [0, 0, 1.0]),
      bone('Spine', 0, [0, 0, 1.1]),
      bone('Chest', 1, [0, 0, 1.2]),
      bone('Neck', 2, [0, 0, 1.4]),
      bone('LeftShoulder', 2, [0, 0.05, 1.35]),
      bone('LeftUpperArm', 4, [0, 0.2, 1.35]),
    ],
  };
}
const restPoses = (s) => s.bones.map((b) => [...b.rest]);
const everything = () => true;

test('HumanBodyBones names map to VRM 1.0 names', () => {
  assert.equal(vrmBoneName('Hips'), 'hips');
  assert.equal(vrmBoneName('LeftUpperArm'), 'leftUpperArm');
  assert.equal(vrmBoneName('RightToes'), 'rightToes');
  assert.equal(vrmBoneName('UpperChest'), 'upperChest');
  assert.equal(vrmBoneName('LeftThumbProximal'), 'leftThumbMetacarpal');
  assert.equal(vrmBoneName('RightThumbIntermediate'), 'rightThumbProximal');
  assert.equal(vrmBoneName('LeftThumbDistal'), 'leftThumbDistal');
  assert.equal(vrmBoneName(''), null);
  assert.equal(vrmBoneName('hips'), null);
  assert.equal(vrmBoneName(7), null);
});

test('at rest every bone is at identity and the hips at their rest', () => {
  const s = scene();
  const rig = makeRig(s, everything);
  const model = { vrm0: false, hipsRest: [0, 0.8, 0], scale: rootScale(rig, [0, 0.8, 0]) };
  assert.ok(Math.abs(model.scale - 0.8) < 1e-12);
  const pose = vrmPose(rig, restPoses(s), model);
  for (const q of Object.values(pose.rotations)) assert.ok(close(q, I), JSON.stringify(q));
  assert.ok(close(pose.hips, [0, 0.8, 0]));
});

test('tonus lowers the left arm: the model\'s left arm points down', () => {
  const s = scene();
  const rig = makeRig(s, everything);
  const poses = restPoses(s);
  // tonus: the arm lies along +Y (left); -90 degrees about +X (forward) sends it to -Z (down).
  poses[5] = [0, 0.2, 1.35, ...about([1, 0, 0], -Math.PI / 2)];
  for (const vrm0 of [false, true]) {
    const pose = vrmPose(rig, poses, { vrm0, hipsRest: [0, 0.8, 0], scale: 1 });
    // The model's left arm lies along +X (VRM 1.0) or -X (0.x, facing -Z); down is -Y in both.
    const arm = vrm0 ? [-1, 0, 0] : [1, 0, 0];
    const down = rotate(pose.rotations.leftUpperArm, arm);
    assert.ok(close(down, [0, -1, 0], 1e-12), `vrm0 ${vrm0}: ${down}`);
    // The arm rotated about the avatar's forward axis: +Z (1.0) or -Z (0.x) stays put.
    const forward = vrm0 ? [0, 0, -1] : [0, 0, 1];
    assert.ok(close(rotate(pose.rotations.leftUpperArm, forward), forward, 1e-12));
  }
});

test('a child\'s rotation is local: the chest turns, the arm turns with it and stays at rest locally', () => {
  const s = scene();
  const rig = makeRig(s, everything);
  const poses = restPoses(s);
  const turn = about([0, 0, 1], 0.4); // tonus yaw
  for (const i of [2, 3, 4, 5]) poses[i] = [...poses[i].slice(0, 3), ...turn];
  const pose = vrmPose(rig, poses, { vrm0: false, hipsRest: [0, 0.8, 0], scale: 1 });
  assert.ok(close(pose.rotations.chest, about([0, 1, 0], 0.4), 1e-12)); // yaw about VRM's up (+Y)
  assert.ok(close(pose.rotations.leftShoulder, I, 1e-12));
  assert.ok(close(pose.rotations.leftUpperArm, I, 1e-12));
});

test('a model without a chest: the neck and shoulder are driven relative to the spine', () => {
  const s = scene();
  const rig = makeRig(s, (name) => name !== 'chest');
  assert.equal(rig.driven.find((b) => b.vrm === 'neck').ancestor, 1);
  const poses = restPoses(s);
  poses[2] = [0, 0, 1.2, ...about([0, 1, 0], 0.3)]; // the chest bends forward; its children follow
  poses[3] = [0, 0, 1.4, ...about([0, 1, 0], 0.3)];
  const pose = vrmPose(rig, poses, { vrm0: false, hipsRest: [0, 0.8, 0], scale: 1 });
  assert.equal(pose.rotations.chest, undefined);
  assert.ok(close(pose.rotations.neck, about([1, 0, 0], 0.3), 1e-12)); // tonus +Y is VRM +X
});

test('the root moves scaled, in the model\'s frame', () => {
  const s = scene();
  const rig = makeRig(s, everything);
  const poses = restPoses(s);
  poses[0] = [0.1, 0.2, 0.9, 0, 0, 0, 1]; // forward 0.1, left 0.2, down 0.1
  const v1 = vrmPose(rig, poses, { vrm0: false, hipsRest: [0, 0.8, 0], scale: 0.8 });
  assert.ok(close(v1.hips, [0.16, 0.72, 0.08], 1e-12), `${v1.hips}`);
  const v0 = vrmPose(rig, poses, { vrm0: true, hipsRest: [0, 0.8, 0], scale: 0.8 });
  assert.ok(close(v0.hips, [-0.16, 0.72, -0.08], 1e-12), `${v0.hips}`);
});

test('an unknown pose (null in the frame) gives no pose; a scene without hips or rest poses is refused', () => {
  const s = scene();
  const rig = makeRig(s, everything);
  const poses = restPoses(s);
  poses[3] = [0, 0, null, 0, 0, 0, 1];
  assert.equal(vrmPose(rig, poses, { vrm0: false, hipsRest: [0, 0.8, 0], scale: 1 }), null);
  assert.equal(vrmPose(rig, null, { vrm0: false, hipsRest: [0, 0.8, 0], scale: 1 }), null);
  assert.throws(() => makeRig(s, (name) => name !== 'hips'), /no Hips/);
  const old = scene();
  delete old.bones[1].rest;
  assert.throws(() => makeRig(old, everything), /no rest pose for Spine/);
});
