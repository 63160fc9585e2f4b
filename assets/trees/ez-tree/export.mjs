// Exports procedural trees from ez-tree (https://github.com/dgreenheck/ez-tree,
// MIT, by Daniel Greenheck) to self-contained OBJ + MTL + texture folders.
//
//   cd assets/trees/ez-tree && npm ci && node export.mjs
//
// Output (relative to assets/trees/):
//   <species>/<species>.obj   y-up, metres, trunk base at the origin
//   <species>/<species>.mtl   materials `bark` and `leaves`
//   <species>/bark_*.jpg, <species>/leaves_*.png   (downscaled copies)
//   <species>/<species>.glb   the same tree as binary glTF 2.0 (glb.mjs)
//   LICENSE.md                provenance, licence text and a summary table
//
// Options:
//   --texture-size N   longest texture side in pixels (default 512);
//                      0 copies the package's original 1024² files unchanged.
//   --out DIR          write the species folders (and LICENSE.md) under DIR
//                      instead of assets/trees/ (e.g. to check a re-run against
//                      the committed files without touching them).
//   --heavy            write only one extra, "production-size" tree for
//                      profiling the bake: DIR/oak-heavy/ (oak-heavy.obj, .mtl,
//                      .glb, textures), about 280k triangles. Needs --out DIR,
//                      and refuses assets/trees/ itself: it is not a bundled
//                      model, never touches the five species folders or
//                      LICENSE.md, and is not for committing (the OBJ is
//                      ~30 MB, the GLB ~20 MB). It is ez-tree's
//                      "Oak Large" preset (its own seed) with more twigs, rounder
//                      branches and many more, smaller leaves; see HEAVY_SMALL_LEAVES below.
//                      Its vertex count is past the 16-bit indices ez-tree
//                      builds its geometry with, so the script re-indexes the
//                      meshes with 32-bit indices (and recomputes the leaf
//                      normals as ez-tree does) before exporting them.
//
//   node export.mjs --heavy --out /tmp/heavy    ->  /tmp/heavy/oak-heavy/
//
//   --dense            With --heavy: write DIR/oak-dense/ instead, the same tree
//                      with the preset's leaf size (4.5 units): the same
//                      triangles, each leaf card about five times the area, the
//                      bake's worst case (rays cross many transparent cards).
//   --preset NAME --seed N
//                      With --heavy: the same overrides on another ez-tree
//                      preset and seed, written to DIR/<first word of NAME,
//                      lower case>-heavy/ (or -dense/ with --dense): a
//                      production-size tree of another kind, for checking the
//                      bake on trees it was not tuned on. Example:
//   node export.mjs --heavy --dense --preset 'Ash Large' --seed 777 --out /tmp/heavy
//                      ->  /tmp/heavy/ash-dense/ (256 477 triangles)
//
// The output is deterministic: ez-tree uses its own seeded RNG, all numbers are
// rounded to a fixed number of decimals, and the textures are re-encoded with
// fixed settings.

import { createHash } from 'node:crypto';
import { mkdirSync, readFileSync, writeFileSync, statSync, existsSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { objToGlb } from './glb.mjs';

// ez-tree loads its textures through THREE.TextureLoader at import time, which
// needs `document.createElementNS('img')`. A stub is enough: we only need the
// geometry and the texture transform (repeat/offset), never the pixels.
globalThis.document = {
  createElementNS: () => ({
    addEventListener() {},
    removeEventListener() {},
    style: {},
    set src(_v) {},
  }),
};

const THREE = await import('three');
const { Tree, TreePreset } = await import('@dgreenheck/ez-tree');
const sharp = (await import('sharp')).default;

// ---------------------------------------------------------------------------
// Configuration
// ---------------------------------------------------------------------------

// One preset per species. The seeds are the presets' own seeds (as shipped in
// the package's preset JSON), so the trees match the ez-tree app's presets;
// they are set explicitly here so the output cannot silently change.
// Medium presets, except where the medium one is heavy: "Ash Medium" (20k
// triangles, 1.7 MB of OBJ) and "Bush 1" (13.9k triangles, 1.1 MB, parts below
// the ground) would take the folder past ~5 MB, so "Ash Small" and "Bush 2"
// are used. Any preset name from TreePreset works here (except "Trellis").
const SPECIES = [
  { name: 'oak', preset: 'Oak Medium', seed: 35729 },
  { name: 'ash', preset: 'Ash Small', seed: 26867 },
  { name: 'aspen', preset: 'Aspen Medium', seed: 18020 },
  { name: 'pine', preset: 'Pine Medium', seed: 13977 },
  { name: 'bush', preset: 'Bush 2', seed: 45590 },
];

// --heavy: one dense tree for profiling, never a bundled species. "Oak Large"
// (10 m) with its own seed; the overrides are applied over the preset with
// TreeOptions.copy. Twigs per level-2 branch 3 -> 6 (420 twigs instead of 240),
// radial segments per level raised (trunk 12 -> 24, ...; segments do not change
// the tree's shape or its random sequence), and 150 leaves per twig instead of
// 10, at 2 units (20 cm) instead of 4.5: 253,680 leaf triangles (63,420 leaves
// of two crossed quads) and ~26k bark triangles.
const HEAVY_SMALL_LEAVES = {
  name: 'oak-heavy',
  preset: 'Oak Large',
  seed: 23399,
  overrides: {
    branch: { children: { 2: 6 }, segments: { 0: 24, 1: 10, 2: 6, 3: 4 } },
    leaves: { count: 150, size: 2 },
  },
};
// --dense: the preset's leaf size.
const HEAVY_DENSE = {
  ...HEAVY_SMALL_LEAVES,
  name: 'oak-dense',
  overrides: { ...HEAVY_SMALL_LEAVES.overrides, leaves: { count: 150 } },
};

const SCALE = 0.1; // ez-tree units -> metres (trees are ~50-100 units tall)
const POS_DECIMALS = 4; // 0.1 mm
const NRM_DECIMALS = 4;
const UV_DECIMALS = 4;

function parseArgs(argv) {
  const args = { textureSize: 512, out: null, heavy: false, dense: false, preset: null, seed: null };
  for (let i = 0; i < argv.length; i++) {
    if (argv[i] === '--texture-size') {
      args.textureSize = Number(argv[++i]);
      if (!Number.isInteger(args.textureSize) || args.textureSize < 0) {
        throw new Error('--texture-size expects a non-negative integer');
      }
    } else if (argv[i] === '--out') {
      args.out = argv[++i];
      if (!args.out) throw new Error('--out expects a directory');
    } else if (argv[i] === '--heavy') {
      args.heavy = true;
    } else if (argv[i] === '--dense') {
      args.dense = true;
    } else if (argv[i] === '--preset') {
      args.preset = argv[++i];
      if (!args.preset) throw new Error('--preset expects an ez-tree preset name');
    } else if (argv[i] === '--seed') {
      args.seed = Number(argv[++i]);
      if (!Number.isInteger(args.seed) || args.seed < 0) {
        throw new Error('--seed expects a non-negative integer');
      }
    } else {
      throw new Error(`unknown argument ${argv[i]}`);
    }
  }
  if (args.dense && !args.heavy) throw new Error('--dense goes with --heavy');
  if ((args.preset === null) !== (args.seed === null)) throw new Error('--preset and --seed go together');
  if (args.preset !== null && !args.heavy) throw new Error('--preset goes with --heavy');
  return args;
}
const ARGS = parseArgs(process.argv.slice(2));

const HERE = dirname(fileURLToPath(import.meta.url));
const TREES = resolve(HERE, '..'); // assets/trees
const OUT_ROOT = ARGS.out === null ? TREES : resolve(ARGS.out);
if (ARGS.heavy && (ARGS.out === null || OUT_ROOT === TREES)) {
  throw new Error('--heavy needs --out DIR, not assets/trees itself (the heavy tree is not a bundled model)');
}
const HEAVY_BASE = ARGS.dense ? HEAVY_DENSE : HEAVY_SMALL_LEAVES;
const HEAVY = ARGS.preset === null
  ? HEAVY_BASE
  : {
      ...HEAVY_BASE,
      name: `${ARGS.preset.split(' ')[0].toLowerCase()}-${ARGS.dense ? 'dense' : 'heavy'}`,
      preset: ARGS.preset,
      seed: ARGS.seed,
    };
const LIST = ARGS.heavy ? [HEAVY] : SPECIES;
const PKG_DIR = join(HERE, 'node_modules', '@dgreenheck', 'ez-tree');
const PKG = JSON.parse(readFileSync(join(PKG_DIR, 'package.json'), 'utf8'));
const THREE_PKG = JSON.parse(readFileSync(join(HERE, 'node_modules', 'three', 'package.json'), 'utf8'));
const ASSETS = join(PKG_DIR, 'src', 'lib', 'assets');

// ---------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------

/** Fixed-decimal number with trailing zeros stripped; never prints "-0". */
function fmt(x, decimals) {
  if (!Number.isFinite(x)) throw new Error(`non-finite number ${x}`);
  let s = x.toFixed(decimals);
  if (s.includes('.')) s = s.replace(/0+$/, '').replace(/\.$/, '');
  if (s === '-0') s = '0';
  return s;
}

/** sRGB hex colour (as ez-tree stores tints) -> "r g b" in 0..1. */
function hexToKd(hex) {
  const r = (hex >> 16) & 255;
  const g = (hex >> 8) & 255;
  const b = hex & 255;
  return [r, g, b].map((c) => fmt(c / 255, 4)).join(' ');
}

/** Deduplicating table for OBJ v / vt / vn lines (1-based indices). */
class Table {
  constructor(prefix) {
    this.prefix = prefix;
    this.map = new Map();
    this.lines = [];
  }
  add(key) {
    let i = this.map.get(key);
    if (i === undefined) {
      this.lines.push(`${this.prefix} ${key}\n`);
      i = this.lines.length;
      this.map.set(key, i);
    }
    return i;
  }
}

function sha256(buf) {
  return createHash('sha256').update(buf).digest('hex');
}

function kib(bytes) {
  return `${(bytes / 1024).toFixed(1)} KiB`;
}

/**
 * Converts one ez-tree mesh to OBJ face lines, adding its vertices to the
 * shared tables. Positions are taken in the tree's local space (the tree and
 * both meshes have identity transforms; asserted below), scaled to metres.
 * UVs have the material's texture transform (repeat/offset, e.g. the bark's
 * textureScale) baked in, so the MTL needs no -s option.
 */
function meshToObj(mesh, tables, stats) {
  const g = mesh.geometry;
  const pos = g.getAttribute('position');
  const nrm = g.getAttribute('normal');
  const uv = g.getAttribute('uv');
  const index = g.getIndex();
  if (!pos || !nrm || !uv || !index) throw new Error(`${mesh.material.name}: missing attribute`);

  const map = mesh.material.map;
  const uvMatrix = new THREE.Matrix3();
  if (map) {
    map.updateMatrix();
    uvMatrix.copy(map.matrix);
  }

  const vIdx = new Array(pos.count);
  const vtIdx = new Array(pos.count);
  const vnIdx = new Array(pos.count);
  const p = new THREE.Vector3();
  const n = new THREE.Vector3();
  const t = new THREE.Vector2();
  for (let i = 0; i < pos.count; i++) {
    p.fromBufferAttribute(pos, i).multiplyScalar(SCALE);
    n.fromBufferAttribute(nrm, i).normalize();
    t.fromBufferAttribute(uv, i).applyMatrix3(uvMatrix);
    vIdx[i] = tables.v.add(
      `${fmt(p.x, POS_DECIMALS)} ${fmt(p.y, POS_DECIMALS)} ${fmt(p.z, POS_DECIMALS)}`,
    );
    vnIdx[i] = tables.vn.add(
      `${fmt(n.x, NRM_DECIMALS)} ${fmt(n.y, NRM_DECIMALS)} ${fmt(n.z, NRM_DECIMALS)}`,
    );
    vtIdx[i] = tables.vt.add(`${fmt(t.x, UV_DECIMALS)} ${fmt(t.y, UV_DECIMALS)}`);
    stats.min.min(p);
    stats.max.max(p);
  }

  // Winding check: three.js front faces are counter-clockwise; count triangles
  // whose geometric normal disagrees with their vertex normals.
  const a = new THREE.Vector3();
  const b = new THREE.Vector3();
  const c = new THREE.Vector3();
  const na = new THREE.Vector3();
  let faces = '';
  let written = 0;
  let degenerate = 0;
  let flipped = 0;
  for (let f = 0; f < index.count; f += 3) {
    const i0 = index.getX(f);
    const i1 = index.getX(f + 1);
    const i2 = index.getX(f + 2);
    // Triangles that collapse once rounded (branch tips taper to a point)
    // draw nothing; leave them out.
    if (vIdx[i0] === vIdx[i1] || vIdx[i1] === vIdx[i2] || vIdx[i0] === vIdx[i2]) {
      degenerate++;
      continue;
    }
    a.fromBufferAttribute(pos, i0);
    b.fromBufferAttribute(pos, i1);
    c.fromBufferAttribute(pos, i2);
    c.sub(b);
    a.sub(b);
    c.cross(a); // (c - b) x (a - b), as in three's computeVertexNormals
    na.fromBufferAttribute(nrm, i0)
      .add(n.fromBufferAttribute(nrm, i1))
      .add(n.fromBufferAttribute(nrm, i2));
    if (c.dot(na) < 0) flipped++;
    faces +=
      `f ${vIdx[i0]}/${vtIdx[i0]}/${vnIdx[i0]}` +
      ` ${vIdx[i1]}/${vtIdx[i1]}/${vnIdx[i1]}` +
      ` ${vIdx[i2]}/${vtIdx[i2]}/${vnIdx[i2]}\n`;
    written++;
  }
  return { faces, source: index.count / 3, written, degenerate, flipped, uvMatrix: uvMatrix.elements };
}

/**
 * ez-tree stores its indices in a Uint16Array, which wraps past 65,535 vertices
 * (the heavy tree's leaves). If the geometry's index is not ez-tree's own index
 * list, re-index with 32 bits; the leaf normals, which ez-tree computes from the
 * index (computeVertexNormals), are recomputed the same way. Returns whether it did.
 */
function widenIndex(mesh, raw, recomputeNormals) {
  const index = mesh.geometry.getIndex();
  let same = index.array.length === raw.length;
  for (let i = 0; same && i < raw.length; i++) same = index.array[i] === raw[i];
  if (same) return false;
  mesh.geometry.setIndex(new THREE.BufferAttribute(new Uint32Array(raw), 1));
  if (recomputeNormals) mesh.geometry.computeVertexNormals();
  return true;
}

/** Writes a (possibly downscaled) copy of a texture; returns the file name. */
async function writeTexture(src, dstDir, dstName, kind) {
  const dst = join(dstDir, dstName);
  if (ARGS.textureSize === 0) {
    writeFileSync(dst, readFileSync(src));
    return dst;
  }
  const img = sharp(src, { sequentialRead: true }).resize(ARGS.textureSize, ARGS.textureSize, {
    fit: 'inside',
    withoutEnlargement: true,
    kernel: 'lanczos3',
  });
  let buf;
  if (kind === 'jpeg') {
    // mozjpeg's defaults without its progressive scans: baseline JPEGs decode
    // everywhere.
    buf = await img
      .jpeg({
        quality: 85,
        progressive: false,
        optimiseCoding: true,
        trellisQuantisation: true,
        overshootDeringing: true,
        quantisationTable: 3,
      })
      .toBuffer();
  } else {
    // Leaves: keep the alpha channel; a 256-colour palette (like the source
    // files) keeps them small. No dithering, so the output is stable.
    buf = await img
      .png({ palette: true, colours: 256, dither: 0, effort: 10, compressionLevel: 9 })
      .toBuffer();
  }
  writeFileSync(dst, buf);
  return dst;
}

/** Re-reads an OBJ + MTL and checks indices, numbers and texture files. */
function verify(objPath) {
  const dir = dirname(objPath);
  const text = readFileSync(objPath, 'utf8');
  let nv = 0;
  let nvt = 0;
  let nvn = 0;
  const faces = [];
  const mtls = new Set();
  let mtllib = null;
  let current = null;
  for (const line of text.split('\n')) {
    if (line === '' || line.startsWith('#')) continue;
    const parts = line.split(' ');
    const tag = parts[0];
    if (tag === 'v' || tag === 'vn' || tag === 'vt') {
      const want = tag === 'vt' ? 2 : 3;
      if (parts.length !== want + 1) throw new Error(`${objPath}: bad line "${line}"`);
      for (const s of parts.slice(1)) {
        if (!/^-?\d+(\.\d{1,4})?$/.test(s)) throw new Error(`${objPath}: bad number "${s}"`);
      }
      if (tag === 'v') nv++;
      else if (tag === 'vt') nvt++;
      else nvn++;
    } else if (tag === 'f') {
      if (parts.length !== 4) throw new Error(`${objPath}: non-triangle "${line}"`);
      if (current === null) throw new Error(`${objPath}: face before usemtl`);
      faces.push(parts.slice(1));
    } else if (tag === 'usemtl') {
      current = parts[1];
      mtls.add(current);
    } else if (tag === 'mtllib') {
      mtllib = parts[1];
    } else if (tag !== 'o' && tag !== 'g' && tag !== 's') {
      throw new Error(`${objPath}: unexpected line "${line}"`);
    }
  }
  for (const f of faces) {
    for (const ref of f) {
      const [v, vt, vn] = ref.split('/').map(Number);
      if (!(v >= 1 && v <= nv && vt >= 1 && vt <= nvt && vn >= 1 && vn <= nvn)) {
        throw new Error(`${objPath}: index out of range in "${f.join(' ')}"`);
      }
    }
  }
  if (!mtllib) throw new Error(`${objPath}: no mtllib`);
  const mtlText = readFileSync(join(dir, mtllib), 'utf8');
  const defined = new Set();
  for (const line of mtlText.split('\n')) {
    const [tag, arg] = line.trim().split(/\s+/);
    if (tag === 'newmtl') defined.add(arg);
    if (tag === 'map_Kd' || tag === 'map_d') {
      if (!existsSync(join(dir, arg))) throw new Error(`${mtllib}: missing texture ${arg}`);
    }
  }
  for (const m of mtls) {
    if (!defined.has(m)) throw new Error(`${objPath}: material ${m} not in ${mtllib}`);
  }
  return { nv, nvt, nvn, nf: faces.length };
}

// ---------------------------------------------------------------------------
// Export
// ---------------------------------------------------------------------------

const results = [];

for (const sp of LIST) {
  const preset = TreePreset[sp.preset];
  if (!preset) throw new Error(`unknown preset ${sp.preset}`);

  const t0 = performance.now();
  const tree = new Tree();
  tree.options.copy(structuredClone(preset));
  tree.options.seed = sp.seed;
  if (sp.overrides) tree.options.copy(structuredClone(sp.overrides));
  tree.generate();
  const widened = [
    widenIndex(tree.branchesMesh, tree.branches.indices, false) && 'bark',
    widenIndex(tree.leavesMesh, tree.leaves.indices, true) && 'leaves',
  ].filter(Boolean);
  const tGenerated = performance.now();
  tree.updateMatrixWorld(true);
  for (const m of [tree, tree.branchesMesh, tree.leavesMesh]) {
    if (!m.matrixWorld.equals(new THREE.Matrix4())) {
      throw new Error(`${sp.name}: non-identity transform on ${m.name || m.type}`);
    }
  }
  if (tree.trellisMesh) throw new Error(`${sp.name}: trellis presets are not supported`);

  const opts = tree.options;
  const barkType = opts.bark.type;
  const leafType = opts.leaves.type;

  // The trunk starts at the origin: check the centre of its first ring.
  {
    const pos = tree.branchesMesh.geometry.getAttribute('position');
    const ring = opts.branch.segments[0];
    const centre = new THREE.Vector3();
    for (let i = 0; i < ring; i++) centre.add(new THREE.Vector3().fromBufferAttribute(pos, i));
    centre.divideScalar(ring);
    if (centre.length() > 1e-4) throw new Error(`${sp.name}: trunk base not at origin`);
  }

  const dir = join(OUT_ROOT, sp.name);
  mkdirSync(dir, { recursive: true });

  // Textures (one bark colour map and one leaf card per species; copies are
  // per folder so each folder is self-contained).
  const barkFile = `bark_${barkType}.jpg`;
  const leafFile = `leaves_${leafType}.png`;
  const barkSrc = join(ASSETS, 'bark', `${barkType}_color_1k.jpg`);
  const leafSrc = join(ASSETS, 'leaves', `${leafType}_color.png`);
  await writeTexture(barkSrc, dir, barkFile, 'jpeg');
  await writeTexture(leafSrc, dir, leafFile, 'png');

  // Geometry
  const tables = { v: new Table('v'), vt: new Table('vt'), vn: new Table('vn') };
  const stats = {
    min: new THREE.Vector3(Infinity, Infinity, Infinity),
    max: new THREE.Vector3(-Infinity, -Infinity, -Infinity),
  };
  const bark = meshToObj(tree.branchesMesh, tables, stats);
  const leaves = meshToObj(tree.leavesMesh, tables, stats);
  // ez-tree's bark has a few small folded triangles where a thin branch bends
  // sharply between two rings (and at tapered tips); they are kept as they are.
  // Leaf cards must all agree with their normals.
  if (leaves.flipped) throw new Error(`${sp.name}: ${leaves.flipped} leaf triangles wound against their normals`);

  const height = stats.max.y; // trunk base is at y = 0
  const overrides = sp.overrides ? `# Preset overrides: ${JSON.stringify(sp.overrides)}\n` : '';
  const header =
    `# ${sp.name}: ez-tree ${PKG.version} preset "${sp.preset}", seed ${sp.seed}\n` +
    overrides +
    `# Generated by assets/trees/ez-tree/export.mjs (three ${THREE_PKG.version}); do not edit.\n` +
    `# Units: metres (ez-tree units x ${SCALE}), y up, trunk base at the origin.\n` +
    `# Faces are counter-clockwise seen from the front (normal side).\n` +
    `# Leaves are alpha-tested cards and should be drawn double-sided.\n` +
    `# Bounds: min ${stats.min.toArray().map((x) => fmt(x, 3)).join(' ')}` +
    ` max ${stats.max.toArray().map((x) => fmt(x, 3)).join(' ')}\n` +
    `# Triangles: bark ${bark.written}, leaves ${leaves.written}\n`;
  const obj =
    header +
    `mtllib ${sp.name}.mtl\n` +
    `o ${sp.name}\n` +
    tables.v.lines.join('') +
    tables.vt.lines.join('') +
    tables.vn.lines.join('') +
    `g bark\nusemtl bark\n` +
    bark.faces +
    `g leaves\nusemtl leaves\n` +
    leaves.faces;

  const mtl =
    `# ${sp.name}: ez-tree ${PKG.version} preset "${sp.preset}", seed ${sp.seed}\n` +
    overrides +
    `# Generated by assets/trees/ez-tree/export.mjs; do not edit.\n` +
    `# Kd is the preset's tint (sRGB, multiplied with the texture).\n` +
    `\n` +
    `# bark: ez-tree bark type "${barkType}", tint #${opts.bark.tint.toString(16).padStart(6, '0')},` +
    ` textureScale ${opts.bark.textureScale.x} x ${opts.bark.textureScale.y} (baked into the UVs)\n` +
    `newmtl bark\n` +
    `Ka 0 0 0\n` +
    `Kd ${hexToKd(opts.bark.tint)}\n` +
    `Ks 0 0 0\n` +
    `d 1\n` +
    `illum 1\n` +
    `map_Kd ${barkFile}\n` +
    `\n` +
    `# leaves: ez-tree leaf type "${leafType}", tint #${opts.leaves.tint.toString(16).padStart(6, '0')},` +
    ` alphaTest ${opts.leaves.alphaTest}, ${opts.leaves.billboard} billboard, double-sided\n` +
    `newmtl leaves\n` +
    `Ka 0 0 0\n` +
    `Kd ${hexToKd(opts.leaves.tint)}\n` +
    `Ks 0 0 0\n` +
    `d 1\n` +
    `illum 1\n` +
    `map_Kd ${leafFile}\n` +
    `map_d ${leafFile}\n`;

  const objPath = join(dir, `${sp.name}.obj`);
  const mtlPath = join(dir, `${sp.name}.mtl`);
  writeFileSync(objPath, obj);
  writeFileSync(mtlPath, mtl);

  const check = verify(objPath);
  if (check.nf !== bark.written + leaves.written) throw new Error(`${sp.name}: face count mismatch`);
  const glb = objToGlb(sp.name, OUT_ROOT);
  if (glb.triangles !== check.nf) throw new Error(`${sp.name}: GLB triangle count mismatch`);

  const tWritten = performance.now();

  const files = [`${sp.name}.obj`, `${sp.name}.mtl`, barkFile, leafFile].map((f) => {
    const buf = readFileSync(join(dir, f));
    return { name: `${sp.name}/${f}`, size: buf.length, sha256: sha256(buf) };
  });

  results.push({ sp, opts, barkType, leafType, bark, leaves, stats, height, check, files });

  console.log(
    `${sp.name.padEnd(6)} ${sp.preset.padEnd(13)} seed ${String(sp.seed).padEnd(6)}` +
      ` height ${height.toFixed(2)} m  bark ${bark.written} tris (${bark.degenerate} degenerate dropped, ${bark.flipped} folded)` +
      `  leaves ${leaves.written} tris  v ${check.nv} vt ${check.nvt} vn ${check.nvn}` +
      `  bounds [${stats.min.toArray().map((x) => x.toFixed(2))}]..[${stats.max.toArray().map((x) => x.toFixed(2))}]`,
  );
  for (const f of files) console.log(`         ${f.name.padEnd(24)} ${kib(f.size).padStart(10)}  ${f.sha256.slice(0, 16)}`);
  if (ARGS.heavy) {
    console.log(
      `         ${`${sp.name}/${sp.name}.glb`.padEnd(24)} ${kib(glb.bytes).padStart(10)}` +
        `\n         preset overrides ${JSON.stringify(sp.overrides)}` +
        `\n         ez-tree vertices: bark ${tree.branches.verts.length / 3}, leaves ${tree.leaves.verts.length / 3};` +
        ` re-indexed with 32 bits: ${widened.join(', ') || 'none'}` +
        `\n         time: generate ${((tGenerated - t0) / 1000).toFixed(2)} s,` +
        ` textures + OBJ/MTL + check + GLB ${((tWritten - tGenerated) / 1000).toFixed(2)} s`,
    );
  }
}

if (ARGS.heavy) {
  console.log(`wrote ${join(OUT_ROOT, HEAVY.name)}/ (not a bundled model; LICENSE.md untouched)`);
  process.exit(0);
}

// ---------------------------------------------------------------------------
// LICENSE.md
// ---------------------------------------------------------------------------

const licenseText = readFileSync(join(PKG_DIR, 'LICENSE'), 'utf8').trim();
const barkCredits = readFileSync(join(ASSETS, 'bark', 'README.md'), 'utf8')
  .split('\n')
  .map((l) => l.trim())
  .filter((l) => /^\w+ - https?:\/\//.test(l));
const usedBark = new Set(results.map((r) => r.barkType));
const usedLeaves = [...new Set(results.map((r) => r.leafType))];
const total = results.reduce((s, r) => s + r.files.reduce((t, f) => t + f.size, 0), 0);
const texNote =
  ARGS.textureSize === 0
    ? 'The textures are unmodified copies of the package files (1024 x 1024).'
    : `The textures are downscaled by the script from the package's 1024 x 1024 files to ` +
      `${ARGS.textureSize} x ${ARGS.textureSize} (bark: JPEG quality 85; leaves: 256-colour PNG with alpha) ` +
      'to keep the repository small. Run `node export.mjs --texture-size 0` for the originals.';

const below = results.filter((r) => r.stats.min.y < -0.01);
const belowGround = below.length
  ? `Parts reach more than 1 cm below y = 0 in: ${below
      .map((r) => `${r.sp.name} (${r.stats.min.y.toFixed(2)} m)`)
      .join(', ')}.`
  : 'No model reaches more than 1 cm below y = 0.';

const md = `# Tree models: provenance and licence

The tree models in this folder (\`${results.map((r) => r.sp.name).join('/`, `')}/\`) are
generated with [EZ-Tree](https://github.com/dgreenheck/ez-tree) by Daniel Greenheck,
npm package [\`@dgreenheck/ez-tree\`](https://www.npmjs.com/package/@dgreenheck/ez-tree)
version ${PKG.version} (MIT licence, reproduced below), and exported to OBJ/MTL by
[\`ez-tree/export.mjs\`](ez-tree/export.mjs). This file is also written by that script.

## Regenerating

\`\`\`sh
cd assets/trees/ez-tree
npm ci            # exact versions from package-lock.json (ez-tree ${PKG.version}, three ${THREE_PKG.version}, sharp)
node export.mjs   # rewrites assets/trees/<species>/ and this LICENSE.md
node glb.mjs      # only re-converts the OBJ folders to GLB (no dependencies)
\`\`\`

\`node export.mjs --out DIR\` writes the same files under DIR instead, e.g. to check a
re-run against the committed ones. \`node export.mjs --heavy --out DIR\` writes only
\`DIR/${HEAVY.name}/\`, one "production-size" tree of about 280k triangles for profiling the
bake ("${HEAVY.preset}" with more twigs, rounder branches and many more, smaller leaves; the
overrides are in the script and in the OBJ header). It is not a bundled model, is not
listed below, and --heavy refuses to write into this folder. Adding \`--dense\` writes
\`DIR/oak-dense/\` instead: the same tree with the preset's leaf size (4.5 units), each leaf
card about five times the area, the bake's worst case.

The output is deterministic (ez-tree uses its own seeded RNG).

## Format

- One folder per species with \`<species>.obj\`, \`<species>.mtl\` and the textures the
  MTL references, so each folder is self-contained.
- Units are metres (ez-tree units x ${SCALE}), y is up, the base of the trunk is at the
  origin (not re-centred on the bounding box). ${belowGround}
- Faces are triangles \`f v/vt/vn\`, counter-clockwise seen from the normal side, in two
  groups/materials: \`bark\` and \`leaves\`. Identical \`v\`/\`vt\`/\`vn\` entries are shared.
- Positions, normals and UVs are rounded to ${POS_DECIMALS} decimals. The bark texture
  repeat of each preset (\`bark.textureScale\`) is baked into the UVs. Triangles that
  collapse to a point (tapered branch tips) are left out.
- UVs use the OBJ convention: v = 0 is the bottom row of the image.
- \`Kd\` is the preset's tint colour (sRGB), to be multiplied with \`map_Kd\`.
- Leaves are alpha-tested cards (\`map_d\` = alpha of the leaf PNG; ez-tree uses an
  alpha test of 0.5, 0.3 for pine) and should be drawn double-sided. Each leaf is two
  crossed quads ("double" billboard).
- \`<species>.glb\` is the same tree as binary glTF 2.0, converted from the OBJ folder by
  [\`ez-tree/glb.mjs\`](ez-tree/glb.mjs): one primitive per material, TEXCOORD_0 = (u, 1 − v),
  baseColorFactor = \`Kd\` decoded to linear, the textures embedded unchanged; the leaves are
  alphaMode MASK with alphaCutoff 0.5 (the test the OBJ's bake applies) and double-sided,
  the bark OPAQUE: the same tree, material for material.
- Only the bark colour maps are exported; the package also has AO, normal and
  roughness maps for each bark, which the MTL does not reference.
- ${texNote}

## Models

| species | preset | seed | bark texture | leaf texture | triangles (bark / leaves) | height (m) | footprint x / z (m) | OBJ | MTL | textures |
|---|---|---|---|---|---|---|---|---|---|---|
${results
  .map((r) => {
    const size = (f) => kib(r.files.find((x) => x.name.endsWith(f)).size);
    const texBytes = r.files.filter((x) => /\.(jpg|png)$/.test(x.name)).reduce((s, x) => s + x.size, 0);
    return (
      `| ${r.sp.name} | ${r.sp.preset} | ${r.sp.seed} | ${r.barkType} | ${r.leafType} |` +
      ` ${r.bark.written} / ${r.leaves.written} | ${r.height.toFixed(2)} |` +
      ` ${(r.stats.max.x - r.stats.min.x).toFixed(1)} / ${(r.stats.max.z - r.stats.min.z).toFixed(1)} |` +
      ` ${size('.obj')} | ${size('.mtl')} | ${kib(texBytes)} |`
    );
  })
  .join('\n')}

Total size of the generated files: ${(total / 1024 / 1024).toFixed(2)} MiB.

Tints (\`Kd\`): ${results
  .map(
    (r) =>
      `${r.sp.name} bark #${r.opts.bark.tint.toString(16).padStart(6, '0')}, leaves #${r.opts.leaves.tint
        .toString(16)
        .padStart(6, '0')}`,
  )
  .join('; ')}.

## Textures

The textures come from the ez-tree package (\`src/lib/assets/\`).

- Bark colour maps (\`bark_*.jpg\`, from \`src/lib/assets/bark/<type>_color_1k.jpg\`). The
  package's \`src/lib/assets/bark/README.md\` gives their sources ("Higher resolution
  textures can be found from the original source"):
${barkCredits
  .filter((l) => usedBark.has(l.split(' ')[0].toLowerCase()))
  .map((l) => `  - ${l.replace(/ - (https?:\/\/\S+)/, ': <$1>')}`)
  .join('\n')}
- Leaf cards (\`leaves_*.png\`, from \`src/lib/assets/leaves/<type>_color.png\`, used:
  ${usedLeaves.join(', ')}). The package gives no separate source for these; they are
  distributed as part of the MIT-licensed package.

## ez-tree licence

\`\`\`text
${licenseText}
\`\`\`
`;
writeFileSync(join(OUT_ROOT, 'LICENSE.md'), md);

console.log(`total ${(total / 1024 / 1024).toFixed(2)} MiB in ${results.length} folders; wrote LICENSE.md`);
