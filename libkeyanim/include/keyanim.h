/* keyanim.h: the C API of keyanim's runtime (libkeyanim_c.so; pkg-config keyanim-c; CMake
 * target keyanim::c). Load a .kanim clip, ask what it holds, sample it: Euler channels, local
 * transforms or model transforms, at a frame position or a time, with or without a cursor.
 * C99, fixed-width types, opaque handles; usable from C#, Python's ctypes, Rust, Zig and the
 * rest through the C ABI. Nothing here needs a C++ header, and no C++ exception crosses it.
 *
 * (The C++ API is <keyanim/keyanim.h> and the headers beside it; this file is <keyanim.h>.)
 *
 * OWNERSHIP
 *   A keyanim_clip is made by keyanim_clip_load* and freed by keyanim_clip_free. Loading copies
 *   what it needs out of the bytes: the caller may free them as soon as the call returns.
 *   A keyanim_cursor is made by keyanim_cursor_create for one clip and freed by
 *   keyanim_cursor_free; it holds a reference to the clip's data, so it may outlive the clip
 *   handle (the data is freed with the last of them).
 *   A keyanim_skeleton pointer (keyanim_clip_skeleton) and every string returned by a
 *   keyanim_clip_* or keyanim_skeleton_* call are borrowed: valid while the clip handle lives.
 *   Freeing NULL is a no-op. Using a handle after freeing it is undefined behaviour, except
 *   that the most recently freed clip or cursor is recognised: freeing it again, or passing
 *   it to any call, returns KEYANIM_INVALID_ARGUMENT (or the call's failure value) instead.
 *
 * THREADS
 *   A clip is immutable: any number of threads may query and sample one clip at once. A cursor
 *   holds playback state: one thread at a time (give each thread its own). Loading and freeing
 *   are thread-safe for distinct handles.
 *
 * ERRORS
 *   Calls that can fail return a keyanim_status (0 is success; keyanim_status_name names one).
 *   Queries that return a value return 0 (or NULL, or KEYANIM_NO_NODE) for a NULL handle or an
 *   index out of range. Any failure also records the last error of the calling thread
 *   (thread-local): its status, and for a load, the section ("header", "SKEL", ...), the
 *   absolute byte offset of the offending field and a sentence. A call that succeeds leaves
 *   the last error as it was (like errno): read it right after the failing call, or clear it
 *   first with keyanim_last_error_clear. Its strings stay valid until the thread's next
 *   failing call.
 *
 * SAMPLING
 *   Frame positions are in frames from 0 (fractional positions are in-betweens), rounded to
 *   binary32 and clamped to the clip, exactly as spec/FORMAT.md Appendix A computes them. A
 *   time in seconds is the frame position seconds / frame_time (0 when frame_time is 0). A NaN
 *   position or time is KEYANIM_INVALID_ARGUMENT. An output buffer smaller than required is
 *   KEYANIM_OUTPUT_TOO_SMALL and is left unchanged; a larger one is fine (the rest untouched).
 *   Sampling never allocates. With a cursor, forward playback is faster; the values are the
 *   same bit for bit.
 *
 * NOT YET
 *   Every load validates the bytes and builds the clip's own image from them (which is why the
 *   bytes need not outlive the call). Viewing bytes the caller keeps without that copy
 *   (keyanim_clip_view), banks of clips, and a skeleton handle shared by every clip of a rig
 *   wait for the runtime profile of the format; a keyanim_skeleton is today one clip's,
 *   borrowed from it.
 */
#ifndef KEYANIM_C_H
#define KEYANIM_C_H

#include <stddef.h>
#include <stdint.h>

#if defined(_WIN32)
#  if defined(KEYANIM_C_BUILDING)
#    define KEYANIM_C_API __declspec(dllexport)
#  else
#    define KEYANIM_C_API __declspec(dllimport)
#  endif
#elif defined(__GNUC__)
#  define KEYANIM_C_API __attribute__((visibility("default")))
#else
#  define KEYANIM_C_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ---- Versions ------------------------------------------------------------------------------ */

/* The library these declarations belong to; keyanim_version() is the one actually loaded. */
#define KEYANIM_C_VERSION_MAJOR 0
#define KEYANIM_C_VERSION_MINOR 2
#define KEYANIM_C_VERSION_PATCH 0

/* The loaded library's version as (major << 16) | (minor << 8) | patch, and as "0.2.0". */
KEYANIM_C_API uint32_t keyanim_version(void);
KEYANIM_C_API const char* keyanim_version_string(void);
/* The .kanim format: the version this library writes by default (rotations as quaternion
 * curves; clips encoded with Euler rotations are written as 3.0 and 4.0, which older decoders
 * read) and the newest it reads, and the oldest major version it reads, as (major << 16) |
 * minor. Every major version in between is read. */
KEYANIM_C_API uint32_t keyanim_format_version(void);
KEYANIM_C_API uint32_t keyanim_format_oldest_version(void);

/* ---- Status codes -------------------------------------------------------------------------- */

/* The same numbers as keyanim::Status in C++: gapped and append-only, never renumbered. */
typedef int32_t keyanim_status;
#define KEYANIM_OK 0
#define KEYANIM_TRUNCATED 10            /* the data ends before a structure it declares */
#define KEYANIM_BAD_SIGNATURE 12        /* not a .kanim file */
#define KEYANIM_UNSUPPORTED_VERSION 14  /* a major format version this library does not read */
#define KEYANIM_RESERVED_BITS_SET 16    /* a reserved bit or enum value is used */
#define KEYANIM_CORRUPT 20              /* a field breaks a rule of the spec */
#define KEYANIM_CHECKSUM_MISMATCH 22    /* the whole-file CRC-32 does not match */
#define KEYANIM_TRAILING_BYTES 24       /* bytes after the checksum */
#define KEYANIM_LIMIT_EXCEEDED 30       /* above a keyanim_decode_limits bound, or out of memory */
#define KEYANIM_ZSTD_ERROR 40           /* zstd refused a compressed stream */
#define KEYANIM_INVALID_ARGUMENT 50     /* NULL handle or pointer, index out of range, NaN ... */
#define KEYANIM_OUTPUT_TOO_SMALL 52     /* the caller's output buffer is too short */
#define KEYANIM_IO_ERROR 60             /* the file could not be read */

/* Short, stable, lower-case name ("checksum_mismatch"); "unknown_status" for other numbers.
 * Never NULL; static storage. */
KEYANIM_C_API const char* keyanim_status_name(keyanim_status status);

/* The calling thread's last failure (see ERRORS above). Section and detail are "" when the
 * failure has none; the offset is 0 when it has none. */
KEYANIM_C_API keyanim_status keyanim_last_error_status(void);
KEYANIM_C_API const char* keyanim_last_error_section(void);
KEYANIM_C_API uint64_t keyanim_last_error_offset(void);
KEYANIM_C_API const char* keyanim_last_error_detail(void);
KEYANIM_C_API void keyanim_last_error_clear(void);

/* ---- Types --------------------------------------------------------------------------------- */

typedef struct keyanim_clip keyanim_clip;          /* a loaded clip */
typedef struct keyanim_cursor keyanim_cursor;      /* playback state for one clip */
typedef struct keyanim_skeleton keyanim_skeleton;  /* a clip's skeleton, borrowed from the clip */

/* One node's transform, 32 bytes (an array of them stays 16-byte aligned): rotation is a unit
 * quaternion (x, y, z, w), translation in the file's length units; as a matrix on column
 * vectors p' = R(rotation) p + translation. pad is always 0. Quaternions are continuous in
 * time (consecutive frames never flip sign), so they blend. */
typedef struct {
  float rotation[4];
  float translation[3];
  float pad;
} keyanim_transform;

/* BVH channel types, as stored in .kanim files. */
#define KEYANIM_CHANNEL_X_POSITION 0
#define KEYANIM_CHANNEL_Y_POSITION 1
#define KEYANIM_CHANNEL_Z_POSITION 2
#define KEYANIM_CHANNEL_X_ROTATION 3
#define KEYANIM_CHANNEL_Y_ROTATION 4
#define KEYANIM_CHANNEL_Z_ROTATION 5

/* Upper bounds checked before anything a file declares is allocated. */
typedef struct {
  uint32_t max_joints;              /* nodes (joints and End Sites); default 65536 */
  uint32_t max_channels;            /* default 262144 */
  uint32_t max_frames;              /* default 16777216, also the most any clip may have */
  uint32_t reserved;                /* must be 0 */
  uint64_t max_keys;                /* default 268435456 */
  uint64_t max_decompressed_bytes;  /* default 1 GiB; also the largest file load_file reads */
} keyanim_decode_limits;

/* Fills `out` with the defaults above. */
KEYANIM_C_API void keyanim_decode_limits_default(keyanim_decode_limits* out);

/* ---- Loading ------------------------------------------------------------------------------- */

/* Validates the bytes completely (spec/FORMAT.md, "Decoder obligations") and makes a clip.
 * Reads every format version from keyanim_format_oldest_version() on. On success *out is the
 * new clip; on failure *out is NULL and the last error says which section and byte offset
 * (inside a zstd-compressed section, the offset of its stored bytes; the detail then gives the
 * offset within the decompressed content). NULL out is KEYANIM_INVALID_ARGUMENT; NULL bytes
 * with size 0 is an empty input (KEYANIM_TRUNCATED). The bytes are not kept. */
KEYANIM_C_API keyanim_status keyanim_clip_load(const uint8_t* bytes, size_t size, keyanim_clip** out);
/* Same with caller-chosen limits (NULL: the defaults). */
KEYANIM_C_API keyanim_status keyanim_clip_load_limited(const uint8_t* bytes, size_t size,
                                                       const keyanim_decode_limits* limits,
                                                       keyanim_clip** out);
/* Reads the whole file (a path in the system's encoding, UTF-8 on Linux), then loads it.
 * KEYANIM_IO_ERROR when it cannot be read; a file larger than max_decompressed_bytes is
 * KEYANIM_LIMIT_EXCEEDED before it is read. */
KEYANIM_C_API keyanim_status keyanim_clip_load_file(const char* path, keyanim_clip** out);
KEYANIM_C_API keyanim_status keyanim_clip_load_file_limited(const char* path,
                                                            const keyanim_decode_limits* limits,
                                                            keyanim_clip** out);
/* Frees a clip (NULL: nothing). Cursors made for it keep its data until they are freed. */
KEYANIM_C_API void keyanim_clip_free(keyanim_clip* clip);

/* ---- Rigs: clips of one skeleton holding it once ------------------------------------------ */

/* Clips of one rig (the same nodes, names, parents, offsets and channel lists) loaded through
 * the same cache share one skeleton and its pose tables in memory: an engine holding many
 * clips of one character holds its skeleton once (keyanim_clip_skeleton_bytes is then the
 * shared part). Thread-safe; rigs are held weakly (a rig lives as long as a clip uses it), so
 * the cache may be freed before or after its clips. */
typedef struct keyanim_rig_cache keyanim_rig_cache;
KEYANIM_C_API keyanim_status keyanim_rig_cache_create(keyanim_rig_cache** out);
/* NULL: nothing. */
KEYANIM_C_API void keyanim_rig_cache_free(keyanim_rig_cache* rigs);
/* Rigs in use by at least one clip loaded through the cache (0 for NULL). */
KEYANIM_C_API uint64_t keyanim_rig_cache_rig_count(const keyanim_rig_cache* rigs);
/* keyanim_clip_load_limited (limits NULL: the defaults) through a rig cache (not NULL). */
KEYANIM_C_API keyanim_status keyanim_clip_load_shared(const uint8_t* bytes, size_t size,
                                                      const keyanim_decode_limits* limits,
                                                      keyanim_rig_cache* rigs, keyanim_clip** out);
/* ---- The runtime profile: a file sampled where it lies (spec/FORMAT.md section 9) ----------- */

/* Like keyanim_clip_load_limited (limits NULL: the defaults; rigs NULL: none, else through that
 * cache), but a runtime-profile file is not copied: the clip samples `bytes` in place, after
 * checking its structure and checksum (in time proportional to its records, not its keys).
 * `bytes` must be at an address that is a multiple of 8 (else KEYANIM_INVALID_ARGUMENT) and must
 * stay alive and unchanged until the clip and every cursor made for it are freed: memory mapped
 * from a file, or an engine's asset buffer. An archive-profile file is decoded as by
 * keyanim_clip_load (the clip then does not use `bytes` after the call). */
KEYANIM_C_API keyanim_status keyanim_clip_view(const uint8_t* bytes, size_t size, const keyanim_decode_limits* limits,
                                               keyanim_rig_cache* rigs, keyanim_clip** out);
/* 1 when the clip's file was of the runtime profile, else 0 (also for NULL). */
KEYANIM_C_API int32_t keyanim_clip_runtime_profile(const keyanim_clip* clip);
/* A runtime-profile clip's content rules (section 9.4: its image is exactly the one its keys
 * make), which loading and viewing do not check; KEYANIM_OK, or KEYANIM_CORRUPT. Costs about
 * an archive file's load: for tools that convert or verify files. KEYANIM_OK for a clip of the
 * archive profile (built from its keys). */
KEYANIM_C_API keyanim_status keyanim_clip_check_content(const keyanim_clip* clip);

/* 64-bit FNV-1a of the rig (each node's name, parent, offset bits, End Site flag and channel
 * list, in node order): equal for clips of one skeleton (0 for NULL). */
KEYANIM_C_API uint64_t keyanim_clip_rig_hash(const keyanim_clip* clip);
/* 1 when both clips hold the very same skeleton in memory (loaded through one cache), else 0. */
KEYANIM_C_API int32_t keyanim_clip_shares_rig(const keyanim_clip* a, const keyanim_clip* b);

/* ---- What a clip holds (0 for a NULL clip) ---------------------------------------------------- */

/* The format version of the file it was loaded from, (major << 16) | minor. */
KEYANIM_C_API uint32_t keyanim_clip_format_version(const keyanim_clip* clip);
KEYANIM_C_API uint32_t keyanim_clip_frame_count(const keyanim_clip* clip);
/* Seconds per frame, as the file says (0 is allowed: then times cannot be sampled). */
KEYANIM_C_API double keyanim_clip_frame_time(const keyanim_clip* clip);
/* (frame_count - 1) * frame_time; 0 for a clip without frames. */
KEYANIM_C_API double keyanim_clip_duration(const keyanim_clip* clip);
/* Values in one frame: what keyanim_clip_sample writes. */
KEYANIM_C_API uint32_t keyanim_clip_channel_count(const keyanim_clip* clip);
KEYANIM_C_API uint64_t keyanim_clip_total_keys(const keyanim_clip* clip);
/* Bytes the clip holds in memory: skeleton_bytes + animation_bytes. The skeleton's part
 * (names, parents, offsets, channel lists, pose tables) is the same for every clip of one rig;
 * the animation's part (keys, records, per-channel facts, notes) is the clip's own. */
KEYANIM_C_API uint64_t keyanim_clip_memory_bytes(const keyanim_clip* clip);
KEYANIM_C_API uint64_t keyanim_clip_skeleton_bytes(const keyanim_clip* clip);
KEYANIM_C_API uint64_t keyanim_clip_animation_bytes(const keyanim_clip* clip);
/* The encoder's informative notes (key=value lines); "" when none, NULL for a NULL clip. */
KEYANIM_C_API const char* keyanim_clip_encoder_notes(const keyanim_clip* clip);

/* ---- The skeleton: nodes (joints and End Sites), parents first ---------------------------- */

/* What keyanim_clip_node_parent and keyanim_skeleton_node_parent return for a NULL handle or
 * a node out of range (-1 is a root). */
#define KEYANIM_NO_NODE (-2)

/* The clip's skeleton: borrowed, valid while the clip handle lives (NULL for a NULL clip). */
KEYANIM_C_API const keyanim_skeleton* keyanim_clip_skeleton(const keyanim_clip* clip);

/* Node count (what keyanim_clip_sample_local/_model write), names and parents, on the clip for
 * convenience: the same as the keyanim_skeleton_* calls on keyanim_clip_skeleton(clip). */
KEYANIM_C_API uint32_t keyanim_clip_node_count(const keyanim_clip* clip);
KEYANIM_C_API const char* keyanim_clip_node_name(const keyanim_clip* clip, uint32_t node);
KEYANIM_C_API int32_t keyanim_clip_node_parent(const keyanim_clip* clip, uint32_t node);

KEYANIM_C_API uint32_t keyanim_skeleton_node_count(const keyanim_skeleton* skeleton);
/* The name as the BVH file spelled it, NUL-terminated ("" for an unnamed End Site); NULL for a
 * node out of range. Names are bytes (UTF-8 when the encoder followed the spec's advice) and
 * may hold any byte, even NUL, since the format lets no decoder refuse one: _name_length is
 * the whole name's length in bytes, of which a C string shows the part before a NUL. */
KEYANIM_C_API const char* keyanim_skeleton_node_name(const keyanim_skeleton* skeleton, uint32_t node);
KEYANIM_C_API uint32_t keyanim_skeleton_node_name_length(const keyanim_skeleton* skeleton, uint32_t node);
/* The parent's index (< node), -1 for a root, KEYANIM_NO_NODE out of range. */
KEYANIM_C_API int32_t keyanim_skeleton_node_parent(const keyanim_skeleton* skeleton, uint32_t node);
/* 1 for an End Site (no channels), 0 for a joint or out of range. */
KEYANIM_C_API int32_t keyanim_skeleton_node_is_end_site(const keyanim_skeleton* skeleton, uint32_t node);
/* The rest translation (BVH OFFSET, bit-exact as read) into out[0..2]. */
KEYANIM_C_API keyanim_status keyanim_skeleton_node_offset(const keyanim_skeleton* skeleton, uint32_t node,
                                                          double out[3]);
/* The node's channels: how many, the column of the first in a frame of keyanim_clip_sample
 * (a node's channels are consecutive), and their types (KEYANIM_CHANNEL_*) in file order, which
 * is also the rotation order: rotations apply in the listed order as R = R1 R2 R3 acting on
 * column vectors (BVH's convention). Out-of-range nodes have 0 channels. */
KEYANIM_C_API uint32_t keyanim_skeleton_node_channel_count(const keyanim_skeleton* skeleton, uint32_t node);
KEYANIM_C_API uint32_t keyanim_skeleton_node_first_channel(const keyanim_skeleton* skeleton, uint32_t node);
KEYANIM_C_API keyanim_status keyanim_skeleton_node_channel_types(const keyanim_skeleton* skeleton, uint32_t node,
                                                                 uint8_t* out, size_t count);
/* The rotation order as text, e.g. "ZXY" (the axes of its rotation channels in order; "" for
 * none), NUL-terminated into out, which must hold at least 4 chars (and one more than the
 * node's rotation channels, if it has more than 3). */
KEYANIM_C_API keyanim_status keyanim_skeleton_node_rotation_order(const keyanim_skeleton* skeleton, uint32_t node,
                                                                  char* out, size_t size);
/* Values in one frame (the same as keyanim_clip_channel_count of its clip). */
KEYANIM_C_API uint32_t keyanim_skeleton_channel_count(const keyanim_skeleton* skeleton);

/* ---- Sampling ------------------------------------------------------------------------------ */

/* Every channel (Euler angles in degrees, positions in length units, in frame column order)
 * into out, which must hold keyanim_clip_channel_count(clip) floats. */
KEYANIM_C_API keyanim_status keyanim_clip_sample(const keyanim_clip* clip, double frame_position, float* out,
                                                 size_t count);
/* Local transforms, one per node (joints and End Sites, node order), into out, which must hold
 * keyanim_clip_node_count(clip): the rotation of the node's Euler channels in their order, and
 * its translation (OFFSET, with the node's position channels replacing components). */
KEYANIM_C_API keyanim_status keyanim_clip_sample_local(const keyanim_clip* clip, double frame_position,
                                                       keyanim_transform* out, size_t count);
/* Model transforms: the local ones composed from the roots (forward kinematics). A model
 * translation is the node's position in the clip's space. */
KEYANIM_C_API keyanim_status keyanim_clip_sample_model(const keyanim_clip* clip, double frame_position,
                                                       keyanim_transform* out, size_t count);
/* The same at a time in seconds. */
KEYANIM_C_API keyanim_status keyanim_clip_sample_time(const keyanim_clip* clip, double seconds, float* out,
                                                      size_t count);
KEYANIM_C_API keyanim_status keyanim_clip_sample_local_time(const keyanim_clip* clip, double seconds,
                                                            keyanim_transform* out, size_t count);
KEYANIM_C_API keyanim_status keyanim_clip_sample_model_time(const keyanim_clip* clip, double seconds,
                                                            keyanim_transform* out, size_t count);

/* ---- Cursors: playback state ---------------------------------------------------------------- */

/* A cursor for `clip` (which it keeps alive). The only failure besides NULL arguments is lack
 * of memory (KEYANIM_LIMIT_EXCEEDED). */
KEYANIM_C_API keyanim_status keyanim_cursor_create(const keyanim_clip* clip, keyanim_cursor** out);
KEYANIM_C_API void keyanim_cursor_free(keyanim_cursor* cursor);
/* The keyanim_clip_sample* calls through the cursor, on the cursor's clip: same arguments,
 * same values, cheaper when positions move forward a little at a time. */
KEYANIM_C_API keyanim_status keyanim_cursor_sample(keyanim_cursor* cursor, double frame_position, float* out,
                                                   size_t count);
KEYANIM_C_API keyanim_status keyanim_cursor_sample_local(keyanim_cursor* cursor, double frame_position,
                                                         keyanim_transform* out, size_t count);
KEYANIM_C_API keyanim_status keyanim_cursor_sample_model(keyanim_cursor* cursor, double frame_position,
                                                         keyanim_transform* out, size_t count);
KEYANIM_C_API keyanim_status keyanim_cursor_sample_time(keyanim_cursor* cursor, double seconds, float* out,
                                                        size_t count);
KEYANIM_C_API keyanim_status keyanim_cursor_sample_local_time(keyanim_cursor* cursor, double seconds,
                                                              keyanim_transform* out, size_t count);
KEYANIM_C_API keyanim_status keyanim_cursor_sample_model_time(keyanim_cursor* cursor, double seconds,
                                                              keyanim_transform* out, size_t count);

#ifdef __cplusplus
}  /* extern "C" */
#endif

#endif /* KEYANIM_C_H */
