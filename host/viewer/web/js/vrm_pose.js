// Driving a VRM avatar's normalized humanoid bones from tonus's pose: pure
// math (no DOM, no three.js), so node's test runner can check it.
//
// Frames. tonus: right-handed, Z up, the avatar faces +X with its left at +Y;
// a frame gives each bone's world rotation, the scene its rest (T-pose) one.
// VRM 1.0: Y up, the model faces +Z with its left at +X, and its normalized
// bones' rest is a T-pose with identity rotations. So tonus's (x, y, z) is
// VRM 1.0's (y, z, x) (a rotation: the page puts the model under a group
// turning VRM axes back into tonus's), and a rotation's vector part goes the
// same way. VRM 0.x models face -Z: three-vrm's rotateVRM0 turns them half a
// turn about Y, so their local values are VRM 1.0's with x and z negated.
//
// Each bone's rotation from its rest, in the world, is q * rest^-1; its
// normalized local rotation is its parent's world one undone, the parent
// being the nearest ancestor the model has (a VRM may lack a neck or a
// chest; bones tonus lacks, an upper chest or fingers, stay at rest).

// HumanBodyBones names whose VRM 1.0 name is not just the first letter
// lowered: Unity's thumb is VRM 1.0's metacarpal, proximal and distal.
const RENAMED = {
  LeftThumbProximal: 'leftThumbMetacarpal',
  LeftThumbIntermediate: 'leftThumbProximal',
  RightThumbProximal: 'rightThumbMetacarpal',
  RightThumbIntermediate: 'rightThumbProximal',
};

// The VRM 1.0 humanoid bone for a HumanBodyBones name ("LeftUpperArm" ->
// "leftUpperArm"), or null.
export function vrmBoneName(name) {
  if (typeof name !== 'string' || !/^[A-Z][A-Za-z]*$/.test(name)) return null;
  return RENAMED[name] ?? name[0].toLowerCase() + name.slice(1);
}

// Quaternions are [x, y, z, w].
export function qmul(a, b) {
  return [
    a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1],
    a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0],
    a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3],
    a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2],
  ];
}

export function qconj(q) {
  return [-q[0], -q[1], -q[2], q[3]];
}

// Unit length; null when it has none (or holds a non-number).
export function qnormalize(q) {
  const n = Math.hypot(q[0], q[1], q[2], q[3]);
  return Number.isFinite(n) && n > 1e-9 ? q.map((c) => c / n) : null;
}

// tonus -> VRM 1.0 (see the top).
export const tonusToVrmVec = (v) => [v[1], v[2], v[0]];
export const tonusToVrmQuat = (q) => [q[1], q[2], q[0], q[3]];
// VRM 1.0 -> a VRM 0.x model's own frame (half a turn about Y).
export const toVrm0Vec = (v) => [-v[0], v[1], -v[2]];
export const toVrm0Quat = (q) => [-q[0], q[1], -q[2], q[3]];

const usable = (a, n) => Array.isArray(a) && a.length === n && a.every((x) => typeof x === 'number' && Number.isFinite(x));

// What to drive: for each scene bone the model has, its VRM name, the nearest
// ancestor the model has (-1: none) and its rest rotation. `has(vrmName)`
// says whether the model has a bone. Throws when the scene or model lacks hips.
export function makeRig(scene, has) {
  const bones = Array.isArray(scene?.bones) ? scene.bones : [];
  const names = bones.map((b) => vrmBoneName(b?.name));
  const driven = [];
  let hips = -1;
  for (let i = 0; i < bones.length; i++) {
    const name = names[i];
    if (!name || !has(name)) continue;
    let a = bones[i].parent;
    const seen = new Set();
    while (Number.isInteger(a) && a >= 0 && a < bones.length && !seen.has(a) && !(names[a] && has(names[a]))) {
      seen.add(a);
      a = bones[a].parent;
    }
    const ancestor = Number.isInteger(a) && a >= 0 && a < bones.length && !seen.has(a) ? a : -1;
    const rest = bones[i].rest;
    if (!usable(rest, 7)) throw new Error(`the scene has no rest pose for ${bones[i].name} (an older tonusd?)`);
    const restRot = qnormalize(rest.slice(3, 7));
    if (!restRot) throw new Error(`the rest pose of ${bones[i].name} is not a rotation`);
    driven.push({ index: i, vrm: name, ancestor, restInv: qconj(restRot) });
    if (name === 'hips') hips = i;
  }
  if (hips < 0) throw new Error('no Hips shared by the scene and the model');
  // Parents before children: an ancestor's world rotation is ready when needed.
  driven.sort((a, b) => a.index - b.index);
  const groundZ = Number.isFinite(scene.ground_z_m) ? scene.ground_z_m : 0;
  return { driven, hips, hipsRest: bones[hips].rest.slice(0, 3), groundZ };
}

// The model's hips height over its tonus counterpart's: tonus's root motion
// is scaled by it, so feet stay on the ground and strides fit the model.
export function rootScale(rig, modelHipsRest) {
  const tonusHeight = rig.hipsRest[2] - rig.groundZ;
  const modelHeight = modelHipsRest[1];
  if (!(tonusHeight > 1e-3) || !(modelHeight > 1e-3)) return 1;
  return modelHeight / tonusHeight;
}

// The normalized local rotations ({vrmName: [x, y, z, w]}) and the hips'
// position in the model's frame for a frame's `poses` (frame.avatar), or
// null when a driven bone's pose is not known (null in the frame).
// `model`: {vrm0, hipsRest: the normalized hips' rest position, scale}.
export function vrmPose(rig, poses, model) {
  if (!Array.isArray(poses)) return null;
  const world = new Map(); // scene index -> world rotation from rest, VRM 1.0 frame
  const rotations = {};
  for (const bone of rig.driven) {
    const pose = poses[bone.index];
    if (!usable(pose, 7)) return null;
    const q = qnormalize(pose.slice(3, 7));
    if (!q) return null;
    const w = tonusToVrmQuat(qmul(q, bone.restInv));
    world.set(bone.index, w);
    const parent = bone.ancestor >= 0 ? world.get(bone.ancestor) : null;
    const local = qnormalize(parent ? qmul(qconj(parent), w) : w);
    rotations[bone.vrm] = model.vrm0 ? toVrm0Quat(local) : local;
  }
  const p = poses[rig.hips];
  const moved = tonusToVrmVec([0, 1, 2].map((k) => model.scale * (p[k] - rig.hipsRest[k])));
  const offset = model.vrm0 ? toVrm0Vec(moved) : moved;
  const hips = [0, 1, 2].map((k) => model.hipsRest[k] + offset[k]);
  return { rotations, hips };
}
