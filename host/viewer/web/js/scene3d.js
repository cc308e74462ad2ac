// The 3D view (three.js): the avatar (simulation B) as shaded shapes from
// the scene's geoms, the reference as a translucent ghost, the objects, the
// ground grid, the ZMP and the support polygon, and contact forces as arrows;
// and, when the scene names one, a VRM avatar driven by the same pose
// (avatar_vrm.js).
// tonus is Z up, three.js Y up: everything of tonus's lives in `world`, a
// group rotated -90 degrees about X (tonus (x, y, z) -> three (x, z, -y)).
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { VrmAvatar } from './avatar_vrm.js';
import { poseUsable, vecUsable } from './format.js';

const MAX_CONTACTS = 64;
const MAX_SUPPORT_POINTS = 64;
const NEWTONS_TO_METRES = 0.001; // a contact arrow is 1 mm per newton ...
const MAX_ARROW_M = 0.8;         // ... up to this
const RELAXED = new THREE.Color(0x3d7fd1);
const STIFF = new THREE.Color(0xe5604d);
const NEUTRAL = new THREE.Color(0x9aa5b4);
const BACKGROUND = 0x15181d;

function shapeGeometry(geom) {
  const r = geom.radius_m ?? 0;
  switch (geom.shape) {
    case 'capsule': {
      // three's capsule is along Y; tonus's along the geom's local z.
      const g = new THREE.CapsuleGeometry(r, 2 * (geom.half_length_m ?? 0), 4, 12);
      g.rotateX(Math.PI / 2);
      return g;
    }
    case 'sphere':
      return new THREE.SphereGeometry(r, 16, 12);
    case 'box': {
      const h = geom.half_extents_m ?? [0, 0, 0];
      return new THREE.BoxGeometry(2 * h[0], 2 * h[1], 2 * h[2]);
    }
    default:
      return null;
  }
}

// True when WebGL runs on a software rasterizer (SwiftShader, llvmpipe: a VM,
// a headless test): antialiasing there costs more than it is worth.
function softwareRendering() {
  try {
    const gl = document.createElement('canvas').getContext('webgl2');
    if (!gl) return false;
    const info = gl.getExtension('WEBGL_debug_renderer_info');
    const name = info ? String(gl.getParameter(info.UNMASKED_RENDERER_WEBGL)) : '';
    gl.getExtension('WEBGL_lose_context')?.loseContext();
    return /swiftshader|llvmpipe|softpipe|software/i.test(name);
  } catch {
    return false;
  }
}

function setPose(object, pos, quat) {
  object.position.set(pos[0], pos[1], pos[2]);
  object.quaternion.set(quat[0], quat[1], quat[2], quat[3]);
  if (object.quaternion.lengthSq() < 1e-12) object.quaternion.identity();
  else object.quaternion.normalize();
}

export class View3D {
  // Throws when WebGL is not available.
  constructor(container) {
    this.container = container;
    this.software = softwareRendering();
    this.renderer = new THREE.WebGLRenderer({ antialias: !this.software });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
    this.renderer.setClearColor(BACKGROUND);
    container.prepend(this.renderer.domElement);

    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(45, 1, 0.02, 100);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.enableDamping = true;
    this.dirty = true; // render on the next animation frame
    this.resetCamera();

    this.scene.add(new THREE.HemisphereLight(0xdde8ff, 0x303030, 1.6));
    const sun = new THREE.DirectionalLight(0xffffff, 1.8);
    sun.position.set(3, 6, 4);
    this.scene.add(sun);

    this.world = new THREE.Group();
    this.world.rotation.x = -Math.PI / 2;
    this.scene.add(this.world);

    this.grid = new THREE.GridHelper(10, 20, 0x4a5563, 0x2b323c);
    this.scene.add(this.grid);

    this.avatarBones = [];
    this.ghostBones = [];
    this.avatarMaterials = []; // one per bone: coloured by its group's stiffness
    this.boneGroups = [];
    this.objects = new Map(); // id -> mesh
    this.objectMaterials = {
      ball: new THREE.MeshStandardMaterial({ color: 0xffa23a, roughness: 0.5 }),
      cube: new THREE.MeshStandardMaterial({ color: 0x9b7bff, roughness: 0.6 }),
    };
    this.ghostMaterial = new THREE.MeshStandardMaterial({
      color: 0x96dcff, transparent: true, opacity: 0.22, depthWrite: false, roughness: 0.9,
    });

    // ZMP: a flat disc; support polygon: a line loop (both on the ground).
    this.zmp = new THREE.Mesh(
      new THREE.CylinderGeometry(0.03, 0.03, 0.004, 20).rotateX(Math.PI / 2),
      new THREE.MeshBasicMaterial({ color: 0xffcf40 }),
    );
    this.zmp.visible = false;
    this.world.add(this.zmp);
    const supportGeometry = new THREE.BufferGeometry();
    supportGeometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(MAX_SUPPORT_POINTS * 3), 3));
    supportGeometry.setDrawRange(0, 0);
    this.support = new THREE.LineLoop(supportGeometry, new THREE.LineBasicMaterial({ color: 0x4cc38a }));
    this.support.frustumCulled = false;
    this.world.add(this.support);

    this.arrows = [];
    for (let i = 0; i < MAX_CONTACTS; i++) {
      const arrow = new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), new THREE.Vector3(), 0.1, 0xff5ad1, 0.04, 0.025);
      arrow.visible = false;
      this.world.add(arrow);
      this.arrows.push(arrow);
    }
    this.showGhost = true;
    this.showContacts = true;
    this.showCapsules = true;
    this.groundZ = 0;
    this.onVrmChange = null; // set by the page: the VRM avatar's state changed
    this.vrm = new VrmAvatar(this.world, (avatar) => {
      this.dirty = true;
      if (this.onVrmChange) this.onVrmChange(avatar);
    });
    this.lastRenderMs = performance.now();

    this.resize();
    this.resizeObserver = new ResizeObserver(() => this.resize());
    this.resizeObserver.observe(container);
  }

  resetCamera() {
    // In front of the avatar (it faces tonus +X), a little to its right and above.
    this.camera.position.set(3.2, 1.7, 1.4);
    this.controls.target.set(0, 0.95, 0);
    this.controls.update();
    this.dirty = true;
  }

  resize() {
    const w = Math.max(1, this.container.clientWidth);
    const h = Math.max(1, this.container.clientHeight);
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.dirty = true;
  }

  clearBones() {
    for (const bone of [...this.avatarBones, ...this.ghostBones]) {
      this.world.remove(bone);
      bone.traverse((o) => { if (o.isMesh) o.geometry.dispose(); });
    }
    for (const m of this.avatarMaterials) m.dispose();
    this.avatarBones = [];
    this.ghostBones = [];
    this.avatarMaterials = [];
  }

  // Builds the avatar and the ghost from a scene message.
  setScene(scene) {
    this.dirty = true;
    this.clearBones();
    this.clearObjects();
    this.groundZ = Number.isFinite(scene.ground_z_m) ? scene.ground_z_m : 0;
    this.grid.position.y = this.groundZ; // tonus z -> three y
    const bones = Array.isArray(scene.bones) ? scene.bones : [];
    this.boneGroups = bones.map((b) => (Number.isInteger(b.group) ? b.group : -1));
    for (let i = 0; i < bones.length; i++) {
      const material = new THREE.MeshStandardMaterial({ color: NEUTRAL, roughness: 0.55, metalness: 0.05 });
      this.avatarMaterials.push(material);
      const bone = new THREE.Group();
      bone.name = bones[i].name;
      bone.visible = false; // until a frame poses it
      const ghost = new THREE.Group();
      ghost.visible = false;
      this.world.add(bone, ghost);
      this.avatarBones.push(bone);
      this.ghostBones.push(ghost);
    }
    for (const geom of Array.isArray(scene.geoms) ? scene.geoms : []) {
      if (!Number.isInteger(geom.bone) || geom.bone < 0 || geom.bone >= bones.length) continue;
      const geometry = shapeGeometry(geom);
      if (!geometry) continue;
      const pos = vecUsable(geom.pos, 3) ? geom.pos : [0, 0, 0];
      const quat = vecUsable(geom.quat, 4) ? geom.quat : [0, 0, 0, 1];
      const solid = new THREE.Mesh(geometry, this.avatarMaterials[geom.bone]);
      setPose(solid, pos, quat);
      this.avatarBones[geom.bone].add(solid);
      const ghost = new THREE.Mesh(geometry, this.ghostMaterial);
      setPose(ghost, pos, quat);
      ghost.renderOrder = 1;
      this.ghostBones[geom.bone].add(ghost);
    }
    this.vrm.setScene(scene);
  }

  clearObjects() {
    for (const mesh of this.objects.values()) {
      this.world.remove(mesh);
      mesh.geometry.dispose();
    }
    this.objects.clear();
  }

  poseBones(bones, poses, visible) {
    for (let i = 0; i < bones.length; i++) {
      const pose = poses?.[i];
      if (!visible || !poseUsable(pose)) {
        bones[i].visible = false; // null (NaN) in a pose: not known, not drawn
        continue;
      }
      bones[i].visible = true;
      setPose(bones[i], pose.slice(0, 3), pose.slice(3, 7));
    }
  }

  // Applies a frame message.
  setFrame(frame) {
    this.dirty = true;
    this.poseBones(this.avatarBones, frame.avatar, this.showCapsules);
    this.poseBones(this.ghostBones, frame.reference, this.showGhost);
    this.vrm.pose(frame);

    const stiffness = Array.isArray(frame.stiffness) ? frame.stiffness : [];
    for (let i = 0; i < this.avatarMaterials.length; i++) {
      const level = stiffness[this.boneGroups[i]];
      if (Number.isFinite(level)) this.avatarMaterials[i].color.copy(RELAXED).lerp(STIFF, Math.min(1, Math.max(0, level)));
      else this.avatarMaterials[i].color.copy(NEUTRAL);
    }

    this.setObjects(Array.isArray(frame.objects) ? frame.objects : []);
    this.setContacts(this.showContacts && Array.isArray(frame.contacts) ? frame.contacts : []);

    const lift = this.groundZ + 0.003;
    if (vecUsable(frame.zmp, 2)) {
      this.zmp.visible = true;
      this.zmp.position.set(frame.zmp[0], frame.zmp[1], lift);
    } else {
      this.zmp.visible = false;
    }
    const points = (Array.isArray(frame.support) ? frame.support : []).filter((p) => vecUsable(p, 2));
    const n = Math.min(points.length, MAX_SUPPORT_POINTS);
    const position = this.support.geometry.getAttribute('position');
    for (let i = 0; i < n; i++) position.setXYZ(i, points[i][0], points[i][1], lift);
    position.needsUpdate = true;
    this.support.geometry.setDrawRange(0, n >= 2 ? n : 0);
  }

  setObjects(objects) {
    const seen = new Set();
    for (const o of objects) {
      if (!vecUsable(o.pos, 3) || !Number.isFinite(o.size_m) || o.size_m <= 0) continue;
      const key = `${o.id}`;
      seen.add(key);
      let mesh = this.objects.get(key);
      if (mesh && (mesh.userData.kind !== o.kind || mesh.userData.size !== o.size_m)) {
        this.world.remove(mesh);
        mesh.geometry.dispose();
        this.objects.delete(key);
        mesh = undefined;
      }
      if (!mesh) {
        const geometry = o.kind === 'cube'
          ? new THREE.BoxGeometry(o.size_m, o.size_m, o.size_m)
          : new THREE.SphereGeometry(o.size_m, 20, 14); // a ball's size is its radius (frame.hpp)
        mesh = new THREE.Mesh(geometry, this.objectMaterials[o.kind] ?? this.objectMaterials.ball);
        mesh.userData = { kind: o.kind, size: o.size_m };
        this.world.add(mesh);
        this.objects.set(key, mesh);
      }
      setPose(mesh, o.pos, vecUsable(o.quat, 4) ? o.quat : [0, 0, 0, 1]);
    }
    for (const [key, mesh] of this.objects) {
      if (!seen.has(key)) {
        this.world.remove(mesh);
        mesh.geometry.dispose();
        this.objects.delete(key);
      }
    }
  }

  setContacts(contacts) {
    const dir = new THREE.Vector3();
    const origin = new THREE.Vector3();
    let used = 0;
    for (const c of contacts) {
      if (used >= MAX_CONTACTS) break;
      if (!vecUsable(c.pos, 3) || !vecUsable(c.force_n, 3)) continue;
      dir.set(c.force_n[0], c.force_n[1], c.force_n[2]);
      const newtons = dir.length();
      if (newtons < 1e-3) continue;
      const length = Math.min(MAX_ARROW_M, Math.max(0.02, newtons * NEWTONS_TO_METRES));
      const arrow = this.arrows[used++];
      origin.set(c.pos[0], c.pos[1], c.pos[2]);
      arrow.position.copy(origin);
      arrow.setDirection(dir.normalize());
      arrow.setLength(length, Math.min(0.05, 0.3 * length), Math.min(0.03, 0.18 * length));
      arrow.visible = true;
    }
    for (let i = used; i < this.arrows.length; i++) this.arrows[i].visible = false;
  }

  get objectCount() {
    return this.objects.size;
  }

  // Renders when a frame, the camera (orbit controls, their damping) or the
  // size changed since the last call; returns whether it did.
  render() {
    const moved = this.controls.update();
    if (!moved && !this.dirty) return false;
    this.dirty = false;
    const now = performance.now();
    this.vrm.update((now - this.lastRenderMs) / 1000);
    this.lastRenderMs = now;
    this.renderer.render(this.scene, this.camera);
    return true;
  }
}
