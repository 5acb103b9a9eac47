// A pose dump (docs/pose-dump.md) of what three.js plays: a glTF file loaded by GLTFLoader or an FBX file by
// FBXLoader, its animation played by AnimationMixer, every node's `matrixWorld` written at every key time of the
// clip. Compare it with the source:
//
//   cd tests/threejs && npm ci                    # three.js, pinned in tests/threejs/package.json
//   node ../../examples/dump_threejs.mjs FILE.glb|FILE.fbx [CLIP] > three.dump.json
//   bonescope fit FILE.glb three.dump.json
//
// three.js is found in `node_modules` of the folder THREE_DIR names (default: the current one). CLIP is the
// animation's name (default: the first). Matrices are column-major (`elements`), Y up, in metres for glTF and in
// the FBX file's own unit and axes for FBX (FBXLoader converts neither).

import { readFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const [file, clipName] = process.argv.slice(2);
if (!file) {
  console.error('usage: node dump_threejs.mjs FILE.glb [CLIP] > FILE.dump.json');
  process.exit(2);
}
// Both imported from the same three.js, so that the loader's objects are this module's classes.
const three = resolve(process.env.THREE_DIR ?? '.', 'node_modules/three');
const THREE = await import(pathToFileURL(join(three, 'build/three.module.js')));
const loaders = join(three, 'examples/jsm/loaders');

const bytes = readFileSync(file);
const buffer = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
const fbx = file.toLowerCase().endsWith('.fbx');
const gltf = fbx ? await loadFbx(buffer) : await loadGltf(buffer);
const clip = clipName ? gltf.animations.find((c) => c.name === clipName) : gltf.animations[0];
if (!clip) {
  console.error(`no animation ${clipName ?? ''} in ${file}`);
  process.exit(2);
}

// Every object made from a node of the file, parents before children as traverse visits them; a node's parent is
// its nearest ancestor among them. GLTFLoader keeps the node's own name in userData.name (`name` is sanitised);
// FBXLoader names each object after its model (sanitised too), and the group it returns is no node of the file.
const nodes = [];
gltf.scene.traverse((object) => {
  if (fbx ? object !== gltf.scene : object.userData.name !== undefined) {
    object.userData.name ??= object.name;
    nodes.push(object);
  }
});
const named = new Set(nodes);
const parentOf = (object) => {
  for (let p = object.parent; p; p = p.parent) if (named.has(p)) return p.userData.name;
  return null;
};

// Every key time of every track, in order; LoopOnce and clamped, so that the last time is not wrapped to the first.
const times = [...new Set(clip.tracks.flatMap((track) => [...track.times]))].sort((a, b) => a - b);
const mixer = new THREE.AnimationMixer(gltf.scene);
const action = mixer.clipAction(clip);
action.setLoop(THREE.LoopOnce);
action.clampWhenFinished = true;
action.play();

const out = [];
// glTF is in metres, Y up. FBXLoader keeps the file's unit and its axes, whatever its `UpAxis` says: Y up is right
// for Maya's and Blender's files (a Z-up file's dump must say `"up": "z"`).
const header = { format: 'bonescope-pose-dump', version: 1, space: 'world', order: 'column-major',
  unit: fbx ? gltf.unit : 'm', up: 'y', clip: clip.name,
  source: `three.js r${THREE.REVISION} ${fbx ? 'FBXLoader' : 'GLTFLoader'} + AnimationMixer` };
out.push(JSON.stringify(header).slice(0, -1) + ',\n"bones": ' +
  JSON.stringify(nodes.map((n) => ({ name: n.userData.name, parent: parentOf(n) }))) + ',\n"frames": [');
times.forEach((time, i) => {
  mixer.setTime(time);
  gltf.scene.updateMatrixWorld(true);
  const matrices = nodes.map((n) => Array.from(n.matrixWorld.elements));
  out.push(`${i ? ',' : ''}\n{"time": ${time}, "matrices": ${JSON.stringify(matrices)}}`);
});
out.push('\n]}\n');
process.stdout.write(out.join(''));

// GLTFLoader's result: `scene` and `animations`.
async function loadGltf(buffer) {
  const { GLTFLoader } = await import(pathToFileURL(join(loaders, 'GLTFLoader.js')));
  return new Promise((done, fail) => new GLTFLoader().parse(buffer, '', done, fail));
}

// FBXLoader's group as GLTFLoader's result, with the file's unit in metres.
async function loadFbx(buffer) {
  const { FBXLoader } = await import(pathToFileURL(join(loaders, 'FBXLoader.js')));
  const scene = new FBXLoader().parse(buffer, '');
  // FBXLoader keeps the file's `UnitScaleFactor` (centimetres per unit) without applying it.
  return { scene, animations: scene.animations, unit: (scene.userData.unitScaleFactor ?? 1) / 100 };
}
