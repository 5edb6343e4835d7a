// The failure of a zstd frame (spec 3.2 rule 5), thrown by zstd.js and zstd-blocks.js and
// reported by the caller as zstd_error with the section's place.
class ZstdFailure extends Error {}
export const bad = (detail) => { throw new ZstdFailure(detail); };
export const isZstdFailure = (e) => e instanceof ZstdFailure;
