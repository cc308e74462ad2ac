#!/usr/bin/env node
// Writes small VRM avatars for the viewer's browser tests, made here from
// nothing (no downloaded model): a glTF binary with a humanoid node hierarchy
// in a T-pose and a box mesh on each bone, so it is visible and moves with
// its bones. The proportions are not tonus's (1.5 m, an upper chest tonus
// does not have), so the page's scaling and bone mapping are exercised.
//
//   node tests/viewer/make_vrm.mjs --out-dir DIR
//
// writes DIR/avatar-1.0.vrm (VRMC_vrm 1.0: faces +Z, its left at +X),
// DIR/avatar-0.x.vrm (the VRM 0.x extension: faces -Z, its left at -X) and
// DIR/corrupt.vrm (a well-formed glTF binary container whose JSON is not JSON:
// it passes tonusd's start-up check, and the page must refuse it).
import fs from 'node:fs';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

// VRM 1.0 frame: +X the avatar's left, +Y up, +Z forward; metres.
// [name, parent, offset from the parent's joint]
export const SKELETON = [
  ['hips', null, [0, 0.85, 0]],
  ['spine', 'hips', [0, 0.10, 0]],
  ['chest', 'spine', [0, 0.12, 0]],
  ['upperChest', 'chest', [0, 0.10, 0]],
  ['neck', 'upperChest', [0, 0.12, 0]],
  ['head', 'neck', [0, 0.08, 0]],
  ['leftShoulder', 'upperChest', [0.03, 0.08, 0]],
  ['leftUpperArm', 'leftShoulder', [0.10, 0, 0]],
  ['leftLowerArm', 'leftUpperArm', [0.24, 0, 0]],
  ['leftHand', 'leftLowerArm', [0.22, 0, 0]],
  ['rightShoulder', 'upperChest', [-0.03, 0.08, 0]],
  ['rightUpperArm', 'rightShoulder', [-0.10, 0, 0]],
  ['rightLowerArm', 'rightUpperArm', [-0.24, 0, 0]],
  ['rightHand', 'rightLowerArm', [-0.22, 0, 0]],
  ['leftUpperLeg', 'hips', [0.09, -0.05, 0]],
  ['leftLowerLeg', 'leftUpperLeg', [0, -0.38, 0]],
  ['leftFoot', 'leftLowerLeg', [0, -0.38, 0]],
  ['leftToes', 'leftFoot', [0, -0.04, 0.12]],
  ['rightUpperLeg', 'hips', [-0.09, -0.05, 0]],
  ['rightLowerLeg', 'rightUpperLeg', [0, -0.38, 0]],
  ['rightFoot', 'rightLowerLeg', [0, -0.38, 0]],
  ['rightToes', 'rightFoot', [0, -0.04, 0.12]],
];

// The box of a bone without a child to reach: [offset of its centre, size].
const LEAF_BOX = {
  head: [[0, 0.10, 0.01], [0.18, 0.22, 0.20]],
  leftHand: [[0.08, 0, 0], [0.16, 0.03, 0.08]],
  rightHand: [[-0.08, 0, 0], [0.16, 0.03, 0.08]],
  leftToes: [[0, -0.01, 0.03], [0.08, 0.03, 0.06]],
  rightToes: [[0, -0.01, 0.03], [0.08, 0.03, 0.06]],
};

const THICKNESS = { hips: 0.26, spine: 0.22, chest: 0.26, upperChest: 0.28, neck: 0.07 };

// A unit cube (+-0.5) with flat normals: 24 vertices, 36 indices.
function cube() {
  const positions = [];
  const normals = [];
  const indices = [];
  const faces = [
    [[1, 0, 0], [0, 1, 0], [0, 0, 1]], [[-1, 0, 0], [0, 0, 1], [0, 1, 0]],
    [[0, 1, 0], [0, 0, 1], [1, 0, 0]], [[0, -1, 0], [1, 0, 0], [0, 0, 1]],
    [[0, 0, 1], [1, 0, 0], [0, 1, 0]], [[0, 0, -1], [0, 1, 0], [1, 0, 0]],
  ];
  for (const [n, u, v] of faces) {
    const base = positions.length / 3;
    for (const [su, sv] of [[-1, -1], [1, -1], [1, 1], [-1, 1]]) {
      for (let k = 0; k < 3; k++) positions.push(0.5 * n[k] + 0.5 * su * u[k] + 0.5 * sv * v[k]);
      normals.push(...n);
    }
    indices.push(base, base + 1, base + 2, base, base + 2, base + 3);
  }
  return { positions, normals, indices };
}

// The rotation taking +Y to `dir` (unit), as [x, y, z, w].
function fromY(dir) {
  const [x, y, z] = dir;
  const w = 1 + y;
  if (w < 1e-9) return [1, 0, 0, 0]; // straight down: half a turn about X
  const q = [z, 0, -x, w];
  const n = Math.hypot(...q);
  return q.map((c) => c / n);
}

const norm = (v) => Math.hypot(...v);

// The glTF document and its binary buffer. `version`: '1.0' or '0.x'.
export function buildAvatar(version) {
  // VRM 0.x faces the other way: half a turn about Y (x and z negated, for
  // positions and for a quaternion's vector part alike).
  const mirror = version === '0.x' ? (v) => [-v[0], v[1], -v[2], ...v.slice(3)] : (v) => v;
  const mesh = cube();
  const nodes = [{ name: 'Root', children: [] }];
  const boneNode = {};
  const children = (name) => SKELETON.filter((b) => b[1] === name);
  for (const [name, parent, offset] of SKELETON) {
    const index = nodes.length;
    boneNode[name] = index;
    nodes.push({ name: `J_${name}`, translation: mirror(offset), children: [] });
    nodes[parent === null ? 0 : boneNode[parent]].children.push(index);
  }
  // A box on each bone: from its joint to its first child's, or its leaf box.
  for (const [name] of SKELETON) {
    let centre;
    let rotation = [0, 0, 0, 1];
    let scale;
    const kids = children(name).filter((b) => !b[0].endsWith('Shoulder') && !b[0].endsWith('UpperLeg'));
    if (LEAF_BOX[name]) {
      [centre, scale] = LEAF_BOX[name];
    } else if (kids.length > 0) {
      const to = kids[0][2];
      const length = norm(to);
      centre = to.map((c) => c / 2);
      rotation = fromY(to.map((c) => c / length));
      const t = THICKNESS[name] ?? 0.07;
      scale = [t, length, t * 0.8];
    } else {
      continue;
    }
    const index = nodes.length;
    nodes.push({ name: `mesh_${name}`, mesh: name === 'head' ? 1 : 0, translation: mirror(centre), rotation: mirror(rotation), scale });
    nodes[boneNode[name]].children.push(index);
  }
  for (const n of nodes) if (n.children && n.children.length === 0) delete n.children;

  // One buffer: positions, normals (float32), indices (uint16).
  const pos = Float32Array.from(mesh.positions);
  const nor = Float32Array.from(mesh.normals);
  const idx = Uint16Array.from(mesh.indices);
  const bin = Buffer.concat([Buffer.from(pos.buffer), Buffer.from(nor.buffer), Buffer.from(idx.buffer)]);
  const padded = Buffer.concat([bin, Buffer.alloc((4 - (bin.length % 4)) % 4)]);

  const humanBones = Object.fromEntries(SKELETON.map(([name]) => [name, { node: boneNode[name] }]));
  const doc = {
    asset: { version: '2.0', generator: 'tonus tests/viewer/make_vrm.mjs' },
    scene: 0,
    scenes: [{ nodes: [0] }],
    nodes,
    meshes: [
      { name: 'body', primitives: [{ attributes: { POSITION: 0, NORMAL: 1 }, indices: 2, material: 0 }] },
      { name: 'head', primitives: [{ attributes: { POSITION: 0, NORMAL: 1 }, indices: 2, material: 1 }] },
    ],
    materials: [
      { name: 'body', pbrMetallicRoughness: { baseColorFactor: [0.95, 0.72, 0.18, 1], metallicFactor: 0, roughnessFactor: 0.6 } },
      { name: 'head', pbrMetallicRoughness: { baseColorFactor: [0.35, 0.9, 0.45, 1], metallicFactor: 0, roughnessFactor: 0.6 } },
    ],
    buffers: [{ byteLength: padded.length }],
    bufferViews: [
      { buffer: 0, byteOffset: 0, byteLength: pos.byteLength, target: 34962 },
      { buffer: 0, byteOffset: pos.byteLength, byteLength: nor.byteLength, target: 34962 },
      { buffer: 0, byteOffset: pos.byteLength + nor.byteLength, byteLength: idx.byteLength, target: 34963 },
    ],
    accessors: [
      { bufferView: 0, componentType: 5126, count: pos.length / 3, type: 'VEC3', min: [-0.5, -0.5, -0.5], max: [0.5, 0.5, 0.5] },
      { bufferView: 1, componentType: 5126, count: nor.length / 3, type: 'VEC3' },
      { bufferView: 2, componentType: 5123, count: idx.length, type: 'SCALAR' },
    ],
  };
  if (version === '0.x') {
    doc.extensionsUsed = ['VRM'];
    doc.extensions = {
      VRM: {
        exporterVersion: 'tonus-tests',
        specVersion: '0.0',
        meta: {
          title: 'tonus test avatar (VRM 0.x)', version: '1', author: 'tonus tests',
          allowedUserName: 'Everyone', violentUssageName: 'Disallow', sexualUssageName: 'Disallow',
          commercialUssageName: 'Disallow', licenseName: 'CC0',
        },
        humanoid: { humanBones: SKELETON.map(([name]) => ({ bone: name, node: boneNode[name], useDefaultValues: true })) },
      },
    };
  } else {
    doc.extensionsUsed = ['VRMC_vrm'];
    doc.extensions = {
      VRMC_vrm: {
        specVersion: '1.0',
        meta: {
          name: 'tonus test avatar (VRM 1.0)', version: '1', authors: ['tonus tests'],
          licenseUrl: 'https://vrm.dev/licenses/1.0/', avatarPermission: 'everyone', commercialUsage: 'personalNonProfit',
          allowRedistribution: true, modification: 'allowModificationRedistribution',
        },
        humanoid: { humanBones },
      },
    };
  }
  return { json: JSON.stringify(doc), bin: padded };
}

// The GLB container: header, JSON chunk (space-padded), BIN chunk.
export function glb(jsonText, bin) {
  let json = Buffer.from(jsonText, 'utf8');
  json = Buffer.concat([json, Buffer.alloc((4 - (json.length % 4)) % 4, 0x20)]);
  const chunks = [json, bin].filter((c) => c && c.length > 0);
  const types = [0x4e4f534a, 0x004e4942];
  const length = 12 + chunks.reduce((n, c) => n + 8 + c.length, 0);
  const header = Buffer.alloc(12);
  header.writeUInt32LE(0x46546c67, 0);
  header.writeUInt32LE(2, 4);
  header.writeUInt32LE(length, 8);
  const parts = [header];
  chunks.forEach((c, i) => {
    const h = Buffer.alloc(8);
    h.writeUInt32LE(c.length, 0);
    h.writeUInt32LE(types[i], 4);
    parts.push(h, c);
  });
  return Buffer.concat(parts);
}

function main() {
  const i = process.argv.indexOf('--out-dir');
  if (i < 0 || !process.argv[i + 1]) {
    console.error('usage: node make_vrm.mjs --out-dir DIR');
    process.exit(2);
  }
  const dir = path.resolve(process.argv[i + 1]);
  fs.mkdirSync(dir, { recursive: true });
  for (const version of ['1.0', '0.x']) {
    const { json, bin } = buildAvatar(version);
    const file = path.join(dir, `avatar-${version}.vrm`);
    fs.writeFileSync(file, glb(json, bin));
    console.log(`${file}: ${fs.statSync(file).size} bytes`);
  }
  const corrupt = path.join(dir, 'corrupt.vrm');
  fs.writeFileSync(corrupt, glb('{"asset": {"version": "2.0"}, "nodes": [ this is not JSON', Buffer.alloc(0)));
  console.log(`${corrupt}: ${fs.statSync(corrupt).size} bytes (JSON chunk damaged)`);
}

if (process.argv[1] && import.meta.url === pathToFileURL(path.resolve(process.argv[1])).href) main();
