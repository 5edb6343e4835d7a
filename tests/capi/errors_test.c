/* Bad input through keyanim's C API, from C99: errors_test CLIP.kanim.
 * Every mistake a caller can make, and every damage a file can have that the spec names, must
 * come back as its status code (keyanim.h), with the last error filled in, and never crash;
 * buffers refused are left unchanged. Exit 0, or 1 after listing the failed checks. */
#include <keyanim.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int failures = 0;

#define CHECK(cond)                                                    \
  do {                                                                 \
    if (!(cond)) {                                                     \
      fprintf(stderr, "FAIL line %d: %s (last error: %s: %s)\n", __LINE__, #cond, \
              keyanim_status_name(keyanim_last_error_status()), keyanim_last_error_detail()); \
      ++failures;                                                      \
    }                                                                  \
  } while (0)

static uint8_t* read_file(const char* path, size_t* size) {
  FILE* f = fopen(path, "rb");
  uint8_t* bytes;
  long n;
  if (f == NULL) return NULL;
  fseek(f, 0, SEEK_END);
  n = ftell(f);
  fseek(f, 0, SEEK_SET);
  bytes = malloc((size_t)n + 1);
  if (bytes != NULL && fread(bytes, 1, (size_t)n, f) != (size_t)n) {
    free(bytes);
    bytes = NULL;
  }
  fclose(f);
  *size = (size_t)n;
  return bytes;
}

/* Loading `bytes` fails with `want`, leaves *out NULL and names a section. */
static void load_fails(const uint8_t* bytes, size_t size, keyanim_status want, const char* what) {
  keyanim_clip* clip = (keyanim_clip*)&failures; /* not NULL: the call must set it */
  keyanim_status s = keyanim_clip_load(bytes, size, &clip);
  if (s != want || clip != NULL || keyanim_last_error_section()[0] == '\0') {
    fprintf(stderr, "FAIL %s: status %s (want %s), section '%s'\n", what, keyanim_status_name(s),
            keyanim_status_name(want), keyanim_last_error_section());
    ++failures;
  }
}

static void damaged_files(const uint8_t* good, size_t size) {
  uint8_t* copy = malloc(size + 1);
  memcpy(copy, good, size);
  copy[0] ^= 0xff; /* the signature */
  load_fails(copy, size, KEYANIM_BAD_SIGNATURE, "a broken signature");
  CHECK(keyanim_last_error_offset() == 0);
  memcpy(copy, good, size);
  copy[size / 2] ^= 0x10; /* a body byte, the CRC-32 left as it was */
  load_fails(copy, size, KEYANIM_CHECKSUM_MISMATCH, "a flipped byte");
  load_fails(good, size / 2, KEYANIM_TRUNCATED, "half a file");
  load_fails(good, 10, KEYANIM_TRUNCATED, "ten bytes");
  load_fails(good, 0, KEYANIM_TRUNCATED, "no bytes");
  load_fails(NULL, 0, KEYANIM_TRUNCATED, "NULL bytes, size 0");
  memcpy(copy, good, size);
  copy[size] = 0;
  load_fails(copy, size + 1, KEYANIM_TRAILING_BYTES, "a byte after the checksum");
  free(copy);
}

static void null_arguments(void) {
  keyanim_clip* clip = NULL;
  keyanim_cursor* cursor = NULL;
  float f[4] = {0};
  keyanim_transform t[2];
  keyanim_clip_free(NULL); /* no-ops */
  keyanim_cursor_free(NULL);
  CHECK(keyanim_clip_load_file(NULL, &clip) == KEYANIM_INVALID_ARGUMENT && clip == NULL);
  CHECK(keyanim_clip_load_file("x.kanim", NULL) == KEYANIM_INVALID_ARGUMENT);
  CHECK(keyanim_clip_load(NULL, 5, &clip) == KEYANIM_INVALID_ARGUMENT && clip == NULL);
  CHECK(keyanim_clip_load_file("/nonexistent/dir/x.kanim", &clip) == KEYANIM_IO_ERROR && clip == NULL);
  CHECK(strcmp(keyanim_last_error_section(), "file") == 0 && strstr(keyanim_last_error_detail(), "/nonexistent") != NULL);
  CHECK(keyanim_clip_load_file("/", &clip) != KEYANIM_OK && clip == NULL); /* a directory */
  CHECK(keyanim_clip_sample(NULL, 0.0, f, 4) == KEYANIM_INVALID_ARGUMENT);
  CHECK(keyanim_clip_sample_local(NULL, 0.0, t, 2) == KEYANIM_INVALID_ARGUMENT);
  CHECK(keyanim_clip_sample_model_time(NULL, 0.0, t, 2) == KEYANIM_INVALID_ARGUMENT);
  CHECK(keyanim_cursor_sample(NULL, 0.0, f, 4) == KEYANIM_INVALID_ARGUMENT);
  CHECK(keyanim_cursor_create(NULL, &cursor) == KEYANIM_INVALID_ARGUMENT && cursor == NULL);
  keyanim_last_error_clear();
  CHECK(keyanim_clip_frame_count(NULL) == 0 && keyanim_last_error_status() == KEYANIM_INVALID_ARGUMENT);
  CHECK(keyanim_clip_frame_time(NULL) == 0.0 && keyanim_clip_node_count(NULL) == 0);
  CHECK(keyanim_clip_node_name(NULL, 0) == NULL && keyanim_clip_node_parent(NULL, 0) == KEYANIM_NO_NODE);
  CHECK(keyanim_clip_skeleton(NULL) == NULL && keyanim_skeleton_node_count(NULL) == 0);
  CHECK(keyanim_clip_encoder_notes(NULL) == NULL && keyanim_clip_memory_bytes(NULL) == 0);
}

static void names_and_versions(void) {
  CHECK(strcmp(keyanim_status_name(KEYANIM_OK), "ok") == 0);
  CHECK(strcmp(keyanim_status_name(KEYANIM_CHECKSUM_MISMATCH), "checksum_mismatch") == 0);
  CHECK(strcmp(keyanim_status_name(9999), "unknown_status") == 0);
  CHECK(strcmp(keyanim_status_name(-1), "unknown_status") == 0);
  CHECK(strcmp(keyanim_status_name(70000), "unknown_status") == 0);
  CHECK(keyanim_version() == ((KEYANIM_C_VERSION_MAJOR << 16) | (KEYANIM_C_VERSION_MINOR << 8) | KEYANIM_C_VERSION_PATCH));
  CHECK(keyanim_format_oldest_version() <= keyanim_format_version());
}

static void bad_sampling(const keyanim_clip* clip) {
  const uint32_t nc = keyanim_clip_channel_count(clip), nn = keyanim_clip_node_count(clip);
  float* f = malloc(sizeof(float) * nc);
  keyanim_transform* t = malloc(sizeof(keyanim_transform) * nn);
  uint32_t i;
  int untouched = 1;
  for (i = 0; i < nc; ++i) f[i] = 12345.0f;
  CHECK(keyanim_clip_sample(clip, 1.0, f, nc - 1) == KEYANIM_OUTPUT_TOO_SMALL);
  CHECK(strstr(keyanim_last_error_detail(), "keyanim_clip_sample") != NULL);
  for (i = 0; i < nc; ++i) untouched &= f[i] == 12345.0f;
  CHECK(untouched);
  CHECK(keyanim_clip_sample(clip, 1.0, NULL, nc) == KEYANIM_INVALID_ARGUMENT);
  CHECK(keyanim_clip_sample(clip, NAN, f, nc) == KEYANIM_INVALID_ARGUMENT);
  CHECK(keyanim_clip_sample_time(clip, NAN, f, nc) == KEYANIM_INVALID_ARGUMENT);
  CHECK(keyanim_clip_sample_local_time(clip, NAN, t, nn) == KEYANIM_INVALID_ARGUMENT);
  CHECK(keyanim_clip_sample_model(clip, NAN, t, nn) == KEYANIM_INVALID_ARGUMENT);
  CHECK(keyanim_clip_sample_local(clip, 0.0, t, nn - 1) == KEYANIM_OUTPUT_TOO_SMALL);
  CHECK(keyanim_clip_sample_model(clip, 0.0, t, 0) == KEYANIM_OUTPUT_TOO_SMALL);
  /* Infinite and huge positions are clamped to the clip, as the spec says. */
  CHECK(keyanim_clip_sample(clip, INFINITY, f, nc) == KEYANIM_OK);
  CHECK(keyanim_clip_sample_model(clip, -1e300, t, nn) == KEYANIM_OK);
  CHECK(keyanim_clip_sample_time(clip, 1e300, f, nc) == KEYANIM_OK);
  free(f);
  free(t);
}

static void bad_nodes(const keyanim_clip* clip) {
  const keyanim_skeleton* sk = keyanim_clip_skeleton(clip);
  const uint32_t n = keyanim_clip_node_count(clip);
  double offset[3];
  uint8_t types[6];
  char order[4];
  CHECK(keyanim_clip_node_name(clip, n) == NULL && keyanim_clip_node_parent(clip, n) == KEYANIM_NO_NODE);
  CHECK(keyanim_skeleton_node_is_end_site(sk, n) == 0 && keyanim_skeleton_node_channel_count(sk, n) == 0);
  CHECK(keyanim_skeleton_node_name_length(sk, 0) == 4 && strcmp(keyanim_clip_node_name(clip, 0), "Hips") == 0);
  CHECK(keyanim_skeleton_node_name_length(sk, n) == 0);
  CHECK(keyanim_skeleton_node_offset(sk, n, offset) == KEYANIM_INVALID_ARGUMENT);
  CHECK(keyanim_skeleton_node_offset(sk, 0, NULL) == KEYANIM_INVALID_ARGUMENT);
  CHECK(keyanim_skeleton_node_channel_types(sk, 0, types, 2) == KEYANIM_OUTPUT_TOO_SMALL); /* the root has 6 */
  CHECK(keyanim_skeleton_node_channel_types(sk, 0, types, 6) == KEYANIM_OK);
  CHECK(types[0] == KEYANIM_CHANNEL_X_POSITION && types[3] == KEYANIM_CHANNEL_Z_ROTATION); /* data/cmu_02_01_walk.bvh */
  CHECK(keyanim_skeleton_node_rotation_order(sk, 0, order, 3) == KEYANIM_OUTPUT_TOO_SMALL);
  CHECK(keyanim_skeleton_node_rotation_order(sk, 0, order, 4) == KEYANIM_OK && strcmp(order, "ZYX") == 0);
  CHECK(keyanim_skeleton_node_first_channel(sk, 1) == 6 && keyanim_skeleton_channel_count(sk) == keyanim_clip_channel_count(clip));
  CHECK(keyanim_clip_memory_bytes(clip) == keyanim_clip_skeleton_bytes(clip) + keyanim_clip_animation_bytes(clip));
  CHECK(keyanim_clip_skeleton_bytes(clip) > 0 && keyanim_clip_animation_bytes(clip) > 0);
  CHECK(keyanim_clip_format_version(clip) == keyanim_format_version());
  CHECK(strstr(keyanim_clip_encoder_notes(clip), "encoder=keyanim") != NULL);
}

static void limits(const uint8_t* bytes, size_t size) {
  keyanim_decode_limits l;
  keyanim_clip* clip = NULL;
  keyanim_decode_limits_default(&l);
  CHECK(l.max_joints == 65536 && l.max_decompressed_bytes == (uint64_t)1 << 30 && l.reserved == 0);
  l.max_joints = 2;
  CHECK(keyanim_clip_load_limited(bytes, size, &l, &clip) == KEYANIM_LIMIT_EXCEEDED && clip == NULL);
  keyanim_decode_limits_default(&l);
  l.reserved = 1;
  CHECK(keyanim_clip_load_limited(bytes, size, &l, &clip) == KEYANIM_INVALID_ARGUMENT && clip == NULL);
  CHECK(keyanim_clip_load_limited(bytes, size, NULL, &clip) == KEYANIM_OK && clip != NULL);
  keyanim_clip_free(clip);
}

/* Lifetimes: a cursor outlives its clip handle; the last freed handle is recognised. */
static void lifetimes(const char* path) {
  keyanim_clip *clip = NULL, *other = NULL;
  keyanim_cursor* cursor = NULL;
  float before[200], after[200];
  uint32_t nc;
  CHECK(keyanim_clip_load_file(path, &clip) == KEYANIM_OK);
  nc = keyanim_clip_channel_count(clip);
  CHECK(nc <= 200);
  CHECK(keyanim_clip_sample(clip, 7.25, before, 200) == KEYANIM_OK);
  CHECK(keyanim_cursor_create(clip, &cursor) == KEYANIM_OK);
  keyanim_clip_free(clip);
  CHECK(keyanim_cursor_sample(cursor, 7.25, after, 200) == KEYANIM_OK);
  CHECK(memcmp(before, after, sizeof(float) * nc) == 0);
  /* The handle just freed: refused, not undefined. */
  keyanim_last_error_clear();
  keyanim_clip_free(clip);
  CHECK(keyanim_last_error_status() == KEYANIM_INVALID_ARGUMENT && strstr(keyanim_last_error_detail(), "freed"));
  CHECK(keyanim_clip_sample(clip, 1.0, after, 200) == KEYANIM_INVALID_ARGUMENT);
  CHECK(keyanim_clip_frame_count(clip) == 0);
  keyanim_cursor_free(cursor);
  keyanim_cursor_free(cursor);
  CHECK(keyanim_last_error_status() == KEYANIM_INVALID_ARGUMENT);
  CHECK(keyanim_cursor_sample(cursor, 1.0, after, 200) == KEYANIM_INVALID_ARGUMENT);
  /* A new clip at the freed address (the allocator's choice) is a live clip again. */
  CHECK(keyanim_clip_load_file(path, &other) == KEYANIM_OK);
  CHECK(keyanim_clip_sample(other, 7.25, after, 200) == KEYANIM_OK && memcmp(before, after, sizeof(float) * nc) == 0);
  keyanim_clip_free(other);
}

int main(int argc, char** argv) {
  size_t size = 0;
  uint8_t* bytes;
  keyanim_clip* clip = NULL;
  if (argc != 2) {
    fprintf(stderr, "usage: errors_test CLIP.kanim (data/cmu_02_01_walk.bvh encoded)\n");
    return 2;
  }
  bytes = read_file(argv[1], &size);
  if (bytes == NULL) {
    fprintf(stderr, "errors_test: cannot read %s\n", argv[1]);
    return 1;
  }
  names_and_versions();
  null_arguments();
  damaged_files(bytes, size);
  limits(bytes, size);
  CHECK(keyanim_clip_load(bytes, size, &clip) == KEYANIM_OK);
  free(bytes); /* the clip keeps nothing of them */
  if (clip != NULL) {
    bad_sampling(clip);
    bad_nodes(clip);
  }
  keyanim_clip_free(clip);
  lifetimes(argv[1]);
  printf("errors_test: %d failure(s)\n", failures);
  return failures == 0 ? 0 : 1;
}
