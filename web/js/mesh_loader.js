// The robot's mesh visuals (STL, OBJ, DAE) fetched from the server's /robot-mesh/<n>.<ext> with
// three.js' own loaders. One fetch per URL for the page's lifetime (the robot and its ghost share
// it); each caller gets its own copy to colour.
import * as THREE from 'three';
import { STLLoader } from 'three/addons/loaders/STLLoader.js';
import { OBJLoader } from 'three/addons/loaders/OBJLoader.js';
import { ColladaLoader } from 'three/addons/loaders/ColladaLoader.js';
import { MeshFormat } from './protocol.js';

const cache = new Map();  // url -> Promise<THREE.Object3D>

async function load(url, format) {
  if (format === MeshFormat.Stl) {
    const geometry = await new STLLoader().loadAsync(url);
    geometry.computeVertexNormals();
    return new THREE.Mesh(geometry, new THREE.MeshStandardMaterial());
  }
  if (format === MeshFormat.Obj) return new OBJLoader().loadAsync(url);
  if (format === MeshFormat.Dae) {
    const dae = await new ColladaLoader().loadAsync(url);
    if (!dae?.scene) throw new Error('not a COLLADA file');
    // URDF meshes are in the link frame, z up: undo the loader's turn of Z_UP files to y up.
    dae.scene.rotation.set(0, 0, 0);
    return dae.scene;
  }
  throw new Error(`unknown mesh format ${format}`);
}

// A copy of the mesh at `url` (shared geometry, its own materials); rejects with the reason it
// could not be fetched or read, or when it holds no triangles.
export async function loadMesh(url, format) {
  if (!cache.has(url)) {
    const loading = load(url, format).then((object) => {
      if (triangleVertexCount(object) === 0) throw new Error('no triangles in the file');
      return object;
    });
    cache.set(url, loading);
  }
  const template = await cache.get(url);
  const copy = template.clone(true);
  copy.traverse((o) => {
    if (o.isMesh) o.material = Array.isArray(o.material) ? o.material.map((m) => m.clone()) : o.material.clone();
  });
  return copy;
}

// The vertices of the triangle meshes in `object` (what a test can check was drawn).
export function triangleVertexCount(object) {
  let n = 0;
  object.traverse((o) => { if (o.isMesh) n += o.geometry?.attributes.position?.count ?? 0; });
  return n;
}
