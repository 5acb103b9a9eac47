// A pose dump (docs/pose-dump.md) of what Babylon.js plays: a glTF file loaded by its glTF loader into a NullEngine
// scene, its animation group played, every glTF node's world matrix written at every key time. Compare it with the
// source:
//
//   cd tests/babylonjs && npm ci                  # Babylon.js, pinned in tests/babylonjs/package.json
//   node ../../examples/dump_babylonjs.mjs FILE.glb [CLIP] > babylon.dump.json
//   bonescope fit FILE.glb babylon.dump.json
//
// Babylon.js is found in `node_modules` of the folder BABYLON_DIR names (default: the current one). CLIP is the
// animation group's name (default: the first). Babylon is left-handed: its loader puts the file under a `__root__`
// node that converts, and each matrix is written relative to it, in the file's right-handed metres, Y up.

import { readFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const [file, clipName] = process.argv.slice(2);
if (!file) {
  console.error('usage: node dump_babylonjs.mjs FILE.glb [CLIP] > FILE.dump.json');
  process.exit(2);
}
const modules = resolve(process.env.BABYLON_DIR ?? '.', 'node_modules/@babylonjs');
const BABYLON = await import(pathToFileURL(join(modules, 'core/index.js')));
await import(pathToFileURL(join(modules, 'loaders/glTF/index.js')));

// Babylon logs to standard output, where the dump goes: errors only (to standard error).
BABYLON.Logger.LogLevels = BABYLON.Logger.ErrorLogLevel;
BABYLON.Logger.OnNewCacheEntry = (entry) => console.error(entry);
const engine = new BABYLON.NullEngine();
const scene = new BABYLON.Scene(engine);
new BABYLON.FreeCamera('camera', BABYLON.Vector3.Zero(), scene); // a scene renders only through a camera
const data = `data:;base64,${readFileSync(file).toString('base64')}`;
const container = await BABYLON.LoadAssetContainerAsync(data, scene, { pluginExtension: '.glb' });
container.addAllToScene();
const group = clipName ? scene.animationGroups.find((g) => g.name === clipName) : scene.animationGroups[0];
if (!group) {
  console.error(`no animation ${clipName ?? ''} in ${file}`);
  process.exit(2);
}

// The glTF nodes: every transform node below the loader's `__root__`, parents first, the first of each name (a
// skinned mesh, which the loader hangs beside its node under the node's name, is left out); a node's parent is its
// nearest ancestor among them.
const root = scene.transformNodes.find((n) => n.name === '__root__') ?? scene.meshes.find((n) => n.name === '__root__');
const seen = new Set();
const nodes = root.getDescendants(false).filter((n) => {
  const first = n instanceof BABYLON.TransformNode && !seen.has(n.name);
  seen.add(n.name);
  return first;
});
const named = new Set(nodes);
const parentOf = (node) => {
  for (let p = node.parent; p; p = p.parent) if (named.has(p)) return p.name;
  return null;
};

// Every key time, in seconds, of every animation of the group.
const seconds = new Set();
for (const { animation } of group.targetedAnimations) {
  for (const key of animation.getKeys()) seconds.add(key.frame / animation.framePerSecond);
}
const times = [...seconds].sort((a, b) => a - b);
const rate = group.targetedAnimations[0].animation.framePerSecond;

const header = { format: 'bonescope-pose-dump', version: 1, space: 'world', order: 'column-major', unit: 'm', up: 'y',
  clip: group.name, source: `Babylon.js ${BABYLON.Engine.Version} NullEngine + glTF loader` };
const out = [JSON.stringify(header).slice(0, -1) + ',\n"bones": ' +
  JSON.stringify(nodes.map((n) => ({ name: n.name, parent: parentOf(n) }))) + ',\n"frames": ['];
group.start(false);
group.pause();
times.forEach((time, i) => {
  group.goToFrame(time * rate);
  scene.render();
  root.computeWorldMatrix(true);
  const unconvert = root.getWorldMatrix().clone().invert();
  // Babylon's matrices act on row vectors: their row-major array is the column-vector matrix's column-major one.
  const matrices = nodes.map((n) => Array.from(n.computeWorldMatrix(true).multiply(unconvert).m));
  out.push(`${i ? ',' : ''}\n{"time": ${time}, "matrices": ${JSON.stringify(matrices)}}`);
});
out.push('\n]}\n');
process.stdout.write(out.join(''));
