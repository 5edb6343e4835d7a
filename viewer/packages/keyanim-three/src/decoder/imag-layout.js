// Where IMAG's arrays lie (spec 9.2): a 32-byte header, then each array in this order, each
// padded with zero bytes to a multiple of 8. The one place that knows the order and the sizes.
export const IMAG_HEADER_BYTES = 32;

const pad8 = (n) => Math.ceil(n / 8) * 8;

// counts: { C, nc, nb, B, M, P, Q, QT } from CLIP and IMAG's header (nb <= nc <= C already
// checked; version 5: Q quaternion nodes, QT quaternion tracks, 3 QT <= nb; version 4: Q = QT = 0,
// which leaves the quaternion arrays empty). Returns { arrays: { Name: { at, count, size } },
// end, L, nl, nt, R, LQ }: offsets within IMAG's content (all below 2^53: C, nc, M, P are u32,
// B <= 2^18 since F <= 2^24, Q <= N); nt = nb - 2 QT block tracks, R = B nt records.
export function imageLayout({ C, nc, nb, B, M, P, Q = 0, QT = 0 }) {
  const L = 4 * Math.ceil(nc / 4), nl = nc - nb, nt = nb - 2 * QT, R = B * nt, LQ = 4 * Math.ceil(Q / 4);
  const entries = [
    ['Interpolation', C, 1], ['Tension', C, 4], ['Key_Count', C, 4], ['Curve_Of', C, 4],
    ['Fixed_Value', C, 4], ['Fixed_Frame', C, 4], ['Fixed_Channels', C - nc, 4], ['Curves', nc, 24],
    ['Curve_S', L, 4], ['First_Frame', L, 4], ['Last_Frame', L, 4], ['First_Value', L, 4],
    ['Last_Value', L, 4], ['Curve_Linear', L, 4], ['Curve_Channel', nc, 4],
    ['Quat_Node', Q, 4], ['Quat_Column', Q, 4], ['Quat_Reference', 4 * LQ, 4], ['Lists', nl, 8],
    ['List_Frames', M, 4], ['List_Values', M, 4], ['List_Q', M, 8], ['Record_Offset', R + 8, 4],
    ['Payload', P + 8, 1],
  ];
  const arrays = {};
  let at = IMAG_HEADER_BYTES;
  for (const [name, count, entryBytes] of entries) {
    arrays[name] = { at, count, size: count * entryBytes };
    at += pad8(count * entryBytes);
  }
  return { arrays, end: at, L, nl, nt, R, LQ };
}
