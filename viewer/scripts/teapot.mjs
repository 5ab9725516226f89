// The Utah teapot for the manipulation scenes (paper Fig. 9): three.js's TeapotGeometry (the
// classic Newell Bézier patches, tessellated), written as OBJ in metres, +Y up, its base on
// y = 0 and centred in x and z. Run from viewer/: `node scripts/teapot.mjs`; the output,
// crates/dqhand/data/objects/teapot.obj, is committed. As the original, the surface is made of
// patches: not watertight (seams and the spout and handle openings), which the collision layer
// handles.
import { writeFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { TeapotGeometry } from 'three/examples/jsm/geometries/TeapotGeometry.js';

/** three.js's scale parameter, metres: the teapot comes out 12 cm tall and 24.5 cm from spout to handle. */
const SIZE = 0.06;
const SEGMENTS = 8;

const geometry = new TeapotGeometry(SIZE, SEGMENTS, true, true, true, true, true);
geometry.computeBoundingBox();
const box = geometry.boundingBox;
const [cx, cz, y0] = [(box.min.x + box.max.x) / 2, (box.min.z + box.max.z) / 2, box.min.y];
const position = geometry.getAttribute('position');
const index = geometry.getIndex();
const round = (v) => Number(v.toFixed(6));
const lines = [
  '# Utah teapot (Newell 1975), tessellated by three.js TeapotGeometry; metres, +Y up, base at y = 0',
  `# size ${SIZE}, segments ${SEGMENTS}; written by viewer/scripts/teapot.mjs`,
];
for (let i = 0; i < position.count; i++) {
  lines.push(`v ${round(position.getX(i) - cx)} ${round(position.getY(i) - y0)} ${round(position.getZ(i) - cz)}`);
}
for (let i = 0; i < index.count; i += 3) {
  lines.push(`f ${index.getX(i) + 1} ${index.getX(i + 1) + 1} ${index.getX(i + 2) + 1}`);
}
const out = fileURLToPath(new URL('../../crates/dqhand/data/objects/teapot.obj', import.meta.url));
writeFileSync(out, `${lines.join('\n')}\n`);
console.log(`wrote ${out}: ${position.count} vertices, ${index.count / 3} triangles, ${round(box.max.x - box.min.x)} × ${round(box.max.y - box.min.y)} × ${round(box.max.z - box.min.z)} m`);
