// Compares what Blender played (blender_play.py's JSON) with forward kinematics of the clip's
// BVH (bvh.mjs): every node and every joint's shell points, at every source frame.
//   node blender_compare.mjs CLIP.bvh OUT.glb BLENDER.json
// Prints the largest distance in units of the export's tolerance, per kind of point. Exits 1 if
// a node or shell point is beyond the tolerance (used for LINEAR-only exports, which Blender
// plays as nlerp; CUBICSPLINE tangents are ignored by Blender 3.4's importer, see README).
import fs from 'node:fs';
import path from 'node:path';
import { readBvh, framePoints, pointName } from './bvh.mjs';

const [clipPath, glbPath, blenderPath] = process.argv.slice(2);
const clip = readBvh(clipPath);
const bytes = fs.readFileSync(glbPath);
const json = JSON.parse(new TextDecoder().decode(bytes.subarray(20, 20 + bytes.readUInt32LE(12))));
const { tolerance: tol, shell_distance: shell } = json.asset.extras.keyanim;
const played = JSON.parse(fs.readFileSync(blenderPath, 'utf8'));
let worstNode = [0], worstShell = [0];
for (let f = 0; f < clip.frames; ++f) {
  const m = played.matrices[f];
  const got = m.map((rows) => rows.map((r) => r[3]));
  clip.nodes.forEach((n, j) => {
    if (n.endSite) return;
    for (let a = 0; a < 3; ++a) got.push(m[j].map((r) => r[3] + shell * r[a]));
  });
  const want = framePoints(clip, f, shell);
  for (let p = 0; p < want.length; ++p) {
    const e = Math.hypot(got[p][0] - want[p][0], got[p][1] - want[p][1], got[p][2] - want[p][2]);
    const w = p < clip.nodes.length ? worstNode : worstShell;
    if (!(e <= w[0])) w.splice(0, 3, e, p, f);
  }
}
const where = (w) => (w.length > 1 ? `${pointName(clip, w[1])}, frame ${w[2]}` : '-');
console.log(`${path.basename(glbPath).padEnd(48)} Blender ${played.blender}: nodes ${(worstNode[0] / tol).toFixed(3)} ` +
            `(${where(worstNode)}), shell ${(worstShell[0] / tol).toFixed(3)} (${where(worstShell)}) x tolerance`);
process.exit(worstNode[0] <= tol && worstShell[0] <= tol ? 0 : 1);
