// A Bandai-like BVH written here, for the framing and up-axis tests: like Bandai Namco's files,
// the ROOT (`joint_Root`) stays at the origin while its child `Hips` carries the translation
// (here a walk of 800 units along z over 195 frames at 30 fps, the length of Bandai's walk),
// with legs and arms swinging about x. up 'z' writes the same motion turned +90 degrees about x
// ((x, y, z) -> (x, -z, y)): every rotation here is about x, which the turn keeps, so the z-up
// file's world positions are the y-up file's turned, exactly.
const FRAMES = 195;

// [name, parent index, offset (y-up), rotation channels?]
const JOINTS = [
  ['joint_Root', -1, [0, 0, 0]], ['Hips', 0, [0, 93.9, -3]], ['Spine', 1, [0, 20, 0]], ['Head', 2, [0, 50, 0]],
  ['LeftUpLeg', 1, [10, 0, 0]], ['LeftLeg', 4, [0, -45, 0]], ['RightUpLeg', 1, [-10, 0, 0]], ['RightLeg', 6, [0, -45, 0]],
  ['LeftArm', 2, [20, 45, 0]], ['LeftForeArm', 8, [30, 0, 0]], ['RightArm', 2, [-20, 45, 0]], ['RightForeArm', 10, [-30, 0, 0]],
];
const END_SITES = { Head: [0, 15, 0], LeftLeg: [0, -45, 0], RightLeg: [0, -45, 0], LeftForeArm: [25, 0, 0], RightForeArm: [-25, 0, 0] };
const SWING = { LeftUpLeg: 30, RightUpLeg: -30, LeftLeg: 20, RightLeg: 20, LeftArm: -25, RightArm: 25 };

const turn = (v, up) => (up === 'z' ? [v[0], -v[2], v[1]] : v);
const num = (x) => (Math.abs(x) < 1e-12 ? 0 : Number(x.toFixed(6)));

export function bandaiLikeBvh(up = 'y') {
  const lines = ['HIERARCHY'];
  const write = (i, depth) => {
    const [name, , offset] = JOINTS[i], pad = '  '.repeat(depth);
    lines.push(`${pad}${depth ? 'JOINT' : 'ROOT'} ${name}`, `${pad}{`, `${pad}  OFFSET ${turn(offset, up).map(num).join(' ')}`,
      `${pad}  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation`);
    JOINTS.forEach(([, parent], k) => { if (parent === i) write(k, depth + 1); });
    if (END_SITES[name]) lines.push(`${pad}  End Site`, `${pad}  {`, `${pad}    OFFSET ${turn(END_SITES[name], up).map(num).join(' ')}`, `${pad}  }`);
    lines.push(`${pad}}`);
  };
  write(0, 0);
  lines.push('MOTION', `Frames: ${FRAMES}`, 'Frame Time: 0.0333333');
  for (let f = 0; f < FRAMES; ++f) {
    const phase = (2 * Math.PI * f) / 40;
    const row = JOINTS.flatMap(([name, , offset]) => {
      // Position channels hold the Offset (as Bandai's do), but Hips walks.
      const p = name === 'Hips' ? [0, 90 + 2 * Math.sin(2 * phase), -400 + (800 * f) / (FRAMES - 1)] : offset;
      const x = (SWING[name] ?? 0) * Math.sin(phase);
      return [...turn(p, up), 0, x, 0];
    });
    lines.push(row.map(num).join(' '));
  }
  return `${lines.join('\n')}\n`;
}
