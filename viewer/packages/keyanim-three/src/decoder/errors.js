// The decoder's one error type: a status of spec/FORMAT.md section 7 plus where it happened.

export class KanimError extends Error {
  // status: a name of section 7 ("corrupt", "truncated", ...); where: "section CLIP",
  // "section table", ...; offset: a byte offset (see describeOffset); detail: what is wrong.
  constructor(status, where, offset, detail) {
    super(`${where}, offset ${offset} (0x${offset.toString(16)}): ${status}: ${detail}`);
    this.name = 'KanimError';
    this.status = status;
    this.where = where;
    this.offset = offset;
    this.detail = detail;
  }
}

export function fail(status, where, offset, detail) {
  throw new KanimError(status, where, offset, detail);
}
