// File facts: what the clip holds and what it costs, as label/value rows for the side panel.
const fmt = (v, digits = 4) => Number(v.toPrecision(digits)).toLocaleString('en-US');
const bytes = (n) => (n < 10240 ? `${n} B` : n < 10485760 ? `${fmt(n / 1024, 3)} KiB` : `${fmt(n / 1048576, 3)} MiB`);

// clip: from decodeKanim (or decodeBankClip: clip.bank = { name, index }); original: { name, bytes } of the BVH text, when loaded.
export function clipFacts(clip, original) {
  const joints = clip.nodes.filter((n) => !n.endSite).length;
  const rawF32 = clip.frameCount * clip.channelCount * 4;
  const rows = [
    ['format', `.kanim ${clip.version.major}.${clip.version.minor}, ${clip.profile} profile${clip.bank ? ", a bank's clip" : ''}`],
    ['frames', `${clip.frameCount}`],
    ['fps', clip.frameTime > 0 ? fmt(1 / clip.frameTime, 5) : '-'],
    ['duration', clip.frameTime > 0 ? `${fmt(Math.max(0, clip.frameCount - 1) * clip.frameTime, 4)} s` : '-'],
    ['joints', `${joints} (+${clip.nodes.length - joints} End Sites)`],
    ['channels', `${clip.channelCount}`],
    ...(clip.version.major >= 5 ? [['quaternion nodes', `${clip.quatNodes.length} (rotations stored as quaternion curves)`]] : []),
    ['keys', `${clip.keyCount} (${fmt((100 * clip.keyCount) / Math.max(1, rawF32 / 4), 3)}% of all values)`],
    ['tangent rule', clip.tangentRule === 1 ? 'step_adjusted' : 'uniform'],
    ['bytes', bytes(clip.fileBytes)],
    ['ratio', `${fmt(rawF32 / clip.fileBytes, 3)}x raw float32`],
  ];
  if (clip.bank) rows.push(['in the bank', `clip ${clip.bank.index}: ${clip.bank.name} (bytes: the clip's own)`]);
  if (original) rows.push(['original', `${original.name}: ${bytes(original.bytes)} (${fmt(original.bytes / clip.fileBytes, 3)}x)`]);
  return rows;
}

// Encoder notes: key=value lines (spec 4.6), informative only.
export const noteLines = (clip) => clip.notes.split('\n').filter((l) => l.trim() !== '');

// A BVH shown alone: what it holds, and how to get the .kanim that the viewer compares it with.
// original: from bvh.js's parseBvh, with name and bytes.
export function bvhFacts(original) {
  const joints = original.nodes.filter((n) => !n.endSite).length;
  return [
    ['format', 'BVH (no .kanim loaded)'],
    ['frames', `${original.frameCount}`],
    ['fps', original.frameTime > 0 ? fmt(1 / original.frameTime, 5) : '-'],
    ['duration', original.frameTime > 0 ? `${fmt(Math.max(0, original.frameCount - 1) * original.frameTime, 4)} s` : '-'],
    ['joints', `${joints} (+${original.nodes.length - joints} End Sites)`],
    ['channels', `${original.channelCount}`],
    ['bytes', bytes(original.bytes)],
    ['to compare', `keyanim encode ${original.name} -o ${original.name.replace(/\.bvh$/i, '')}.kanim, then open both`],
  ];
}
