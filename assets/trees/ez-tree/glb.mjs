// Converts an exported tree folder (<species>.obj + .mtl + textures, as written by
// export.mjs) into one self-contained binary glTF 2.0 file, <species>.glb, with the same
// triangles, texture coordinates, normals, materials and texture bytes. No dependencies.
//
//   node glb.mjs [species ...]      (default: every folder export.mjs writes)
//
// What the GLB holds, and how it maps the OBJ:
// - one mesh, one primitive per material, in the OBJ's face order; each distinct
//   `v/vt/vn` triple is one vertex (POSITION with min/max, NORMAL, TEXCOORD_0), indices
//   UNSIGNED_INT; one node at the origin without a transform (y-up, metres, as the OBJ);
// - TEXCOORD_0 = (u, 1 − v): glTF's v runs down the image, the OBJ's up;
// - baseColorFactor = the MTL's `Kd` sRGB-decoded to linear (glTF factors are linear),
//   alpha 1; baseColorTexture = `map_Kd`, its bytes embedded unchanged (JPEG or PNG);
// - a material with `map_d` (the leaves: the same PNG as `map_Kd`, alpha in its alpha
//   channel) is alphaMode MASK with alphaCutoff 0.5 — the test the OBJ's bake and renderers
//   apply — and doubleSided; the others (bark) are OPAQUE and single-sided;
// - metallicFactor 0, roughnessFactor 1 (the MTL has no specular term: `Ks 0 0 0`).
//
// Checked with the Khronos glTF validator (gltf-validator 2.0.0-dev.3.10): no errors,
// warnings or infos for any of the five trees.

import { readFileSync, writeFileSync, renameSync, existsSync } from 'node:fs';
import { dirname, join, extname } from 'node:path';
import { fileURLToPath } from 'node:url';

const HERE = dirname(fileURLToPath(import.meta.url));
const TREES = join(HERE, '..');
export const SPECIES = ['oak', 'ash', 'aspen', 'pine', 'bush'];

const srgbDecode = (c) => (c <= 0.04045 ? c / 12.92 : Math.pow((c + 0.055) / 1.055, 2.4));

function parseMtl(text) {
  const mats = new Map();
  let cur = null;
  for (const raw of text.split('\n')) {
    const line = raw.trim();
    if (!line || line.startsWith('#')) continue;
    const [key, ...rest] = line.split(/\s+/);
    if (key === 'newmtl') {
      cur = { name: rest.join(' '), kd: [1, 1, 1], mapKd: null, mapD: null };
      mats.set(cur.name, cur);
    } else if (cur && key === 'Kd') {
      cur.kd = rest.slice(0, 3).map(Number);
    } else if (cur && key === 'map_Kd') {
      cur.mapKd = rest.join(' ');
    } else if (cur && key === 'map_d') {
      cur.mapD = rest.join(' ');
    }
  }
  return mats;
}

/** The OBJ's faces grouped by material, in order of first use. */
function parseObj(text) {
  const v = [], vt = [], vn = [];
  const groups = new Map();
  let mtllib = null;
  let group = null;
  for (const raw of text.split('\n')) {
    const line = raw.trim();
    if (!line || line.startsWith('#')) continue;
    const [key, ...rest] = line.split(/\s+/);
    if (key === 'v') v.push(rest.slice(0, 3).map(Number));
    else if (key === 'vt') vt.push(rest.slice(0, 2).map(Number));
    else if (key === 'vn') vn.push(rest.slice(0, 3).map(Number));
    else if (key === 'mtllib') mtllib = rest.join(' ');
    else if (key === 'usemtl') {
      const name = rest.join(' ');
      if (!groups.has(name)) groups.set(name, []);
      group = groups.get(name);
    } else if (key === 'f') {
      if (rest.length !== 3) throw new Error(`a face of ${rest.length} vertices: export.mjs writes triangles`);
      if (!group) throw new Error('a face before any usemtl');
      group.push(rest);
    }
  }
  return { v, vt, vn, groups, mtllib };
}

const pad4 = (n) => (n + 3) & ~3;

/** Converts root/<species>/ (default root: assets/trees; export.mjs --out passes its own). */
export function objToGlb(species, root = TREES) {
  const dir = join(root, species);
  const obj = parseObj(readFileSync(join(dir, `${species}.obj`), 'utf8'));
  const mats = parseMtl(readFileSync(join(dir, obj.mtllib), 'utf8'));

  const chunks = []; // binary pieces, each 4-byte aligned
  let binLength = 0;
  const bufferViews = [], accessors = [];
  const addView = (bytes, target) => {
    const offset = binLength;
    chunks.push(bytes);
    const padded = pad4(bytes.length);
    if (padded > bytes.length) chunks.push(Buffer.alloc(padded - bytes.length));
    binLength += padded;
    bufferViews.push({ buffer: 0, byteOffset: offset, byteLength: bytes.length, ...(target ? { target } : {}) });
    return bufferViews.length - 1;
  };
  const addAccessor = (array, type, componentType, target, minMax) => {
    const bytes = Buffer.from(array.buffer, array.byteOffset, array.byteLength);
    const width = { SCALAR: 1, VEC2: 2, VEC3: 3 }[type];
    accessors.push({
      bufferView: addView(bytes, target), componentType, count: array.length / width, type,
      ...(minMax ? minMax : {}),
    });
    return accessors.length - 1;
  };

  const images = [], textures = [], materials = [], primitives = [];
  const imageOf = new Map();
  const texture = (file) => {
    if (!imageOf.has(file)) {
      const bytes = readFileSync(join(dir, file));
      const ext = extname(file).toLowerCase();
      const mimeType = ext === '.png' ? 'image/png' : ext === '.jpg' || ext === '.jpeg' ? 'image/jpeg' : null;
      if (!mimeType) throw new Error(`${file}: glTF holds PNG or JPEG textures only`);
      images.push({ bufferView: addView(bytes), mimeType, name: file });
      textures.push({ source: images.length - 1 });
      imageOf.set(file, textures.length - 1);
    }
    return imageOf.get(file);
  };

  for (const [name, faces] of obj.groups) {
    const m = mats.get(name);
    if (!m) throw new Error(`usemtl ${name}: not in ${obj.mtllib}`);
    const index = new Map();
    const pos = [], nrm = [], uv = [], idx = [];
    for (const face of faces) {
      for (const corner of face) {
        let i = index.get(corner);
        if (i === undefined) {
          const [a, b, c] = corner.split('/').map((s) => parseInt(s, 10) - 1);
          pos.push(...obj.v[a]);
          const t = obj.vt[b];
          uv.push(t[0], 1 - t[1]);
          nrm.push(...obj.vn[c]);
          i = index.size;
          index.set(corner, i);
        }
        idx.push(i);
      }
    }
    const p = new Float32Array(pos);
    const min = [Infinity, Infinity, Infinity], max = [-Infinity, -Infinity, -Infinity];
    for (let k = 0; k < p.length; k++) {
      min[k % 3] = Math.min(min[k % 3], p[k]);
      max[k % 3] = Math.max(max[k % 3], p[k]);
    }
    const attributes = {
      POSITION: addAccessor(p, 'VEC3', 5126, 34962, { min, max }),
      NORMAL: addAccessor(new Float32Array(nrm), 'VEC3', 5126, 34962),
      TEXCOORD_0: addAccessor(new Float32Array(uv), 'VEC2', 5126, 34962),
    };
    const indices = addAccessor(new Uint32Array(idx), 'SCALAR', 5125, 34963);
    const masked = m.mapD !== null;
    if (masked && m.mapD !== m.mapKd) {
      throw new Error(`${name}: map_d ${m.mapD} differs from map_Kd ${m.mapKd}; glTF takes alpha from the base colour texture`);
    }
    materials.push({
      name,
      pbrMetallicRoughness: {
        baseColorFactor: [...m.kd.map(srgbDecode), 1],
        ...(m.mapKd ? { baseColorTexture: { index: texture(m.mapKd) } } : {}),
        metallicFactor: 0,
        roughnessFactor: 1,
      },
      alphaMode: masked ? 'MASK' : 'OPAQUE',
      ...(masked ? { alphaCutoff: 0.5 } : {}),
      doubleSided: masked,
    });
    primitives.push({ attributes, indices, material: materials.length - 1, mode: 4 });
  }

  const gltf = {
    asset: { version: '2.0', generator: 'forest assets/trees/ez-tree/glb.mjs' },
    scene: 0,
    scenes: [{ nodes: [0] }],
    nodes: [{ mesh: 0, name: species }],
    meshes: [{ name: species, primitives }],
    materials, textures, images,
    samplers: [],
    accessors, bufferViews,
    buffers: [{ byteLength: binLength }],
  };
  delete gltf.samplers;
  const json = Buffer.from(JSON.stringify(gltf), 'utf8');
  const jsonPadded = Buffer.concat([json, Buffer.alloc(pad4(json.length) - json.length, 0x20)]);
  const bin = Buffer.concat(chunks);
  const header = Buffer.alloc(12);
  const total = 12 + 8 + jsonPadded.length + 8 + bin.length;
  header.writeUInt32LE(0x46546c67, 0); // "glTF"
  header.writeUInt32LE(2, 4);
  header.writeUInt32LE(total, 8);
  const chunkHeader = (length, type) => {
    const h = Buffer.alloc(8);
    h.writeUInt32LE(length, 0);
    h.writeUInt32LE(type, 4);
    return h;
  };
  const out = Buffer.concat([
    header,
    chunkHeader(jsonPadded.length, 0x4e4f534a), jsonPadded, // "JSON"
    chunkHeader(bin.length, 0x004e4942), bin, // "BIN\0"
  ]);
  const path = join(dir, `${species}.glb`);
  // Written under a temporary name, then renamed: never a half-written model.
  writeFileSync(`${path}.tmp`, out);
  renameSync(`${path}.tmp`, path);
  return { path, bytes: out.length, triangles: primitives.reduce((n, p) => n + accessors[p.indices].count / 3, 0) };
}

if (process.argv[1] === fileURLToPath(import.meta.url)) {
  const list = process.argv.length > 2 ? process.argv.slice(2) : SPECIES.filter((s) => existsSync(join(TREES, s)));
  for (const s of list) {
    const r = objToGlb(s);
    console.log(`${s}: ${r.triangles} triangles -> ${r.path} (${(r.bytes / 1024).toFixed(1)} KiB)`);
  }
}
