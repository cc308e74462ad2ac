// The optional VRM avatar (docs/viewer.md): loaded from the one URL the scene
// names (tonusd --vrm FILE) with three.js's GLTFLoader and three-vrm's
// VRMLoaderPlugin, and driven by simulation B's pose each frame through its
// normalized humanoid bones (vrm_pose.js has the frames). three-vrm is
// imported only when a scene announces an avatar, so a page without one
// never needs it. Whatever goes wrong (the file, three-vrm, a pose) ends in
// state 'failed' with a message; nothing here throws into the frame loop.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { makeRig, rootScale, vrmPose } from './vrm_pose.js';

// VRM 1.0 axes (x left, y up, z forward) into tonus's (x forward, y left, z
// up): 120 degrees about (1, 1, 1).
const VRM_TO_TONUS = new THREE.Quaternion(0.5, 0.5, 0.5, 0.5);

const describe = (error) => (error && error.message ? error.message : String(error));

export class VrmAvatar {
  // `parent`: a group in tonus's frame (the view's world); `onChange()` is
  // called when the state changes.
  constructor(parent, onChange = () => {}) {
    this.parent = parent;
    this.onChange = onChange;
    this.state = 'none'; // none | loading | loaded | failed
    this.message = '';
    this.info = null; // the scene's vrm: {url, name, bytes}
    this.version = null; // '1' or '0'
    this.visible = true;
    this.vrm = null;
    this.root = null;
    this.rig = null;
    this.model = null;
    this.applied = null; // {tick, rotations, hips}: the last pose set
    this.loads = 0;
  }

  // A scene arrived: load its avatar, keep the one loaded when it is the same
  // file, or drop it when the scene has none.
  setScene(scene) {
    const info = scene && scene.vrm && typeof scene.vrm.url === 'string' ? scene.vrm : null;
    const same = info && this.info && info.url === this.info.url && info.name === this.info.name &&
      info.bytes === this.info.bytes && this.state !== 'failed';
    if (same) {
      this.scene = scene;
      if (this.state !== 'loaded') return; // the load under way takes this scene
      try {
        this.rigFor(scene);
      } catch (error) {
        this.fail(`${this.info.name} could not be used: ${describe(error)}`);
      }
      return;
    }
    this.clear();
    this.info = info;
    this.scene = scene;
    if (info) this.load(info);
    else this.set('none', '');
  }

  set(state, message) {
    this.state = state;
    this.message = message;
    try {
      this.onChange(this);
    } catch (error) {
      console.error('vrm: onChange', error);
    }
  }

  fail(message) {
    this.clear();
    this.set('failed', message);
  }

  clear() {
    this.loads++; // a load still running is dropped when it ends
    if (this.root) this.parent.remove(this.root);
    if (this.vrm && this.vrmUtils) {
      try {
        this.vrmUtils.deepDispose(this.vrm.scene);
      } catch {
        // disposing is best effort
      }
    }
    this.vrm = null;
    this.root = null;
    this.rig = null;
    this.model = null;
    this.applied = null;
  }

  async load(info) {
    const token = ++this.loads;
    const size = Number.isFinite(info.bytes) ? ` (${(info.bytes / 1e6).toFixed(1)} MB)` : '';
    this.set('loading', `loading ${info.name}${size}…`);
    try {
      let module;
      try {
        module = await import('@pixiv/three-vrm');
      } catch (error) {
        throw new Error(`three-vrm did not load (${describe(error)}): is it installed? run scripts/install-deps.sh`);
      }
      const reply = await fetch(info.url, { cache: 'no-store' });
      if (!reply.ok) throw new Error(`the server answered ${reply.status}: ${(await reply.text()).trim()}`);
      const bytes = await reply.arrayBuffer();
      const loader = new GLTFLoader();
      loader.register((parser) => new module.VRMLoaderPlugin(parser));
      let gltf;
      try {
        gltf = await loader.parseAsync(bytes, '');
      } catch (error) {
        throw new Error(`not a readable glTF: ${describe(error)}`);
      }
      if (token !== this.loads) return; // another scene came meanwhile
      const vrm = gltf.userData.vrm;
      if (!vrm || !vrm.humanoid) {
        throw new Error('no VRM humanoid in it (neither the VRMC_vrm 1.0 nor the VRM 0.x extension): export it as .vrm');
      }
      this.vrmUtils = module.VRMUtils;
      module.VRMUtils.rotateVRM0(vrm);
      this.vrm = vrm;
      this.version = vrm.meta && vrm.meta.metaVersion === '0' ? '0' : '1';
      // Skinned meshes keep their rest bounds: never cull them as they move.
      vrm.scene.traverse((o) => { o.frustumCulled = false; });
      this.root = new THREE.Group();
      this.root.name = 'vrm';
      this.root.quaternion.copy(VRM_TO_TONUS);
      this.root.add(vrm.scene);
      this.rigFor(this.scene);
      this.root.visible = this.visible;
      this.parent.add(this.root);
      this.set('loaded', `${info.name}: VRM ${this.version === '0' ? '0.x' : '1.0'}, driven by simulation B`);
    } catch (error) {
      if (token !== this.loads) return;
      this.fail(`${info.name} could not be used: ${describe(error)}`);
    }
  }

  // Which bones to drive for `scene` (throws when the model and scene share no hips).
  rigFor(scene) {
    this.scene = scene;
    const humanoid = this.vrm.humanoid;
    this.rig = makeRig(scene, (name) => humanoid.getNormalizedBoneNode(name) != null);
    const hipsRest = humanoid.normalizedRestPose.hips?.position ?? [0, 1, 0];
    this.model = { vrm0: this.version === '0', hipsRest, scale: rootScale(this.rig, hipsRest) };
    this.root.position.set(0, 0, this.rig.groundZ);
  }

  setVisible(visible) {
    this.visible = visible;
    if (this.root) this.root.visible = visible;
  }

  // Poses the model from a frame's avatar poses.
  pose(frame) {
    if (this.state !== 'loaded' || !this.visible) return;
    try {
      const pose = vrmPose(this.rig, frame.avatar, this.model);
      if (!pose) return; // a bone not known in this frame: keep the last pose
      const humanoid = this.vrm.humanoid;
      for (const [name, q] of Object.entries(pose.rotations)) {
        humanoid.getNormalizedBoneNode(name).quaternion.set(q[0], q[1], q[2], q[3]);
      }
      humanoid.getNormalizedBoneNode('hips').position.set(pose.hips[0], pose.hips[1], pose.hips[2]);
      this.applied = { tick: frame.tick, rotations: pose.rotations, hips: pose.hips };
    } catch (error) {
      this.fail(`${this.info ? this.info.name : 'the VRM'} stopped: ${describe(error)}`);
    }
  }

  // Before each render: the normalized pose into the model's own bones, spring bones, look-at.
  update(deltaS) {
    if (this.state !== 'loaded' || !this.visible) return;
    try {
      this.vrm.update(Math.min(0.1, Math.max(0, deltaS)));
    } catch (error) {
      this.fail(`${this.info ? this.info.name : 'the VRM'} stopped: ${describe(error)}`);
    }
  }

  // For tests: a raw (skinned) bone's world position in three.js's frame.
  rawWorldPosition(name) {
    const node = this.vrm?.humanoid.getRawBoneNode(name);
    if (!node) return null;
    return node.getWorldPosition(new THREE.Vector3()).toArray();
  }

  normalizedLocal(name) {
    const node = this.vrm?.humanoid.getNormalizedBoneNode(name);
    return node ? node.quaternion.toArray() : null;
  }
}
