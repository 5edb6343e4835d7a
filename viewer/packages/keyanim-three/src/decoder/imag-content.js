// The content rules of spec 9.4: every derived field of IMAG is what 9.2 and 9.3 make from the
// recovered keys. A decoder MAY check them; this one does, by rebuilding each field from the
// keys (work in proportion to the records and keys, which the decoder reads anyway), so that a
// file it accepts samples the same in every conforming player.
const bitWidth = (x) => (x === 0n ? 0 : x.toString(2).length);  // x >= 0
const zigzag = (d) => (d >= 0 ? 2 * d : -2 * d - 1);

export function checkContent(img, curves) {
  for (const cv of curves) {
    checkCurve(img, cv);
    if (cv.list) continue;
    let before = 0;  // keys of the curve before the record's block
    for (const rec of cv.records) { checkRecord(img, cv, rec, before); before += rec.m; }
  }
}

// Q_Base, Base_Bits, and a block curve's First_Value and Last_Value.
function checkCurve(img, cv) {
  const { r } = img, e = img.a.Curves.at + 24 * cv.index;
  let lo = cv.q[0], hi = cv.q[0];
  for (const q of cv.q) { if (q < lo) lo = q; if (q > hi) hi = q; }
  if (cv.qBase !== lo) r.fail('corrupt', e, `curve ${cv.index}: Q_Base ${cv.qBase}, its smallest q is ${lo}`);
  if (cv.baseBits !== bitWidth(hi - lo)) r.fail('corrupt', e + 16, `curve ${cv.index}: Base_Bits ${cv.baseBits}, its q span ${hi - lo} takes ${bitWidth(hi - lo)} bits`);
  if (cv.list) return;
  for (const [name, want] of [['First_Value', cv.values[0]], ['Last_Value', cv.values[cv.n - 1]]]) {
    if (!Object.is(cv[name], want)) r.fail('corrupt', img.a[name].at + 4 * cv.index, `curve ${cv.index}: ${name} ${cv[name]}, not ${want} (its ${name === 'First_Value' ? 'first' : 'last'} key)`);
  }
}

// Key i of the curve extended by virtual keys (9.3): [frame, q].
function windowKey(cv, i) {
  const k = cv.frames, n = cv.n;
  if (i < 0) return [k[0] + (k[1] - k[0]) * i, cv.q[0]];
  if (i >= n) return [k[n - 1] + (k[n - 1] - k[n - 2]) * (i - n + 1), cv.q[n - 1]];
  return [k[i], cv.q[i]];
}

// The record's window (keys f-2, f-1, l, l+1), Base, Value_Bits, Context_Bits and Context.
function checkRecord(img, cv, rec, f) {
  const l = f + rec.m, start = 64 * rec.b;
  const outer = [f - 2, f - 1, l, l + 1].map((i) => windowKey(cv, i));
  const qs = [outer[0][1], outer[1][1], ...cv.q.slice(f, l), outer[2][1], outer[3][1]];
  let lo = qs[0], hi = qs[0];
  for (const q of qs) { if (q < lo) lo = q; if (q > hi) hi = q; }
  const bad = (what) => img.r.fail('corrupt', rec.base, `${rec.what}: ${what} (9.3 makes the record from the curve's keys)`);
  if (rec.baseValue !== lo - cv.qBase) bad(`Base ${rec.baseValue}, not ${lo - cv.qBase}`);
  if (rec.w !== bitWidth(hi - lo)) bad(`Value_Bits ${rec.w}, not ${bitWidth(hi - lo)}`);
  [0, 1, rec.m + 2, rec.m + 3].forEach((j, k) => {
    if (rec.fields[j] !== outer[k][1] - lo) bad(`Values[${j}] ${rec.fields[j]}, not ${outer[k][1] - lo}`);
  });
  const offsets = outer.map(([frame], k) => frame - start - (k >= 2 ? 64 : 0));
  outer.forEach(([frame], k) => { if (rec.ctx[k] !== frame) bad(`context frame e_${k} ${rec.ctx[k]}, not ${frame}`); });
  const wk = bitWidth(BigInt(offsets.reduce((or, d) => or | zigzag(d), 0)));
  if (rec.wk !== wk) bad(`Context_Bits ${rec.wk}, not ${wk}`);
}
