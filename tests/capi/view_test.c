/* The runtime profile through the C API, from C99: view_test WALK.kanim WALK.runtime.kanim.
 * The runtime file viewed in place (keyanim_clip_view) and loaded (copied) give the archive
 * file's poses bit for bit; it says its profile and version; its content check passes; a view
 * through a rig cache shares the archive clip's skeleton; a misaligned address, a changed byte
 * (checksum_mismatch) and NULL bytes are refused; an archive file through view() is decoded
 * and outlives its bytes. Exit 0, or 1 after listing the failed checks. (Content breaks behind
 * a repaired XXH64 are tested in C++: runtime_profile_test.cpp.) */
#include <keyanim.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int failures = 0;

#define CHECK(cond)                                                                      \
  do {                                                                                   \
    if (!(cond)) {                                                                       \
      fprintf(stderr, "FAIL line %d: %s (last error: %s)\n", __LINE__, #cond,            \
              keyanim_last_error_detail());                                              \
      ++failures;                                                                        \
    }                                                                                    \
  } while (0)

/* The file in 8-aligned memory (malloc's alignment is at least 8), one spare byte after it. */
static uint8_t* read_file(const char* path, size_t* size) {
  FILE* f = fopen(path, "rb");
  uint8_t* bytes = NULL;
  long n;
  if (f == NULL) return NULL;
  fseek(f, 0, SEEK_END);
  n = ftell(f);
  fseek(f, 0, SEEK_SET);
  if (n > 0) bytes = malloc((size_t)n + 16);
  if (bytes != NULL && fread(bytes, 1, (size_t)n, f) != (size_t)n) {
    free(bytes);
    bytes = NULL;
  }
  fclose(f);
  *size = (size_t)n;
  return bytes;
}

/* Channels, local and model poses of both clips at positions between and on frames. */
static int same_poses(const keyanim_clip* a, const keyanim_clip* b) {
  uint32_t n = keyanim_clip_node_count(a), c = keyanim_clip_channel_count(a);
  keyanim_transform* p = calloc(n, sizeof *p);
  keyanim_transform* q = calloc(n, sizeof *q);
  float* u = calloc(c, sizeof *u);
  float* v = calloc(c, sizeof *v);
  int same = p != NULL && q != NULL && u != NULL && v != NULL && n == keyanim_clip_node_count(b) &&
             c == keyanim_clip_channel_count(b);
  double f;
  for (f = 0.0; same && f < keyanim_clip_frame_count(a); f += 3.3) {
    same = keyanim_clip_sample_model(a, f, p, n) == KEYANIM_OK && keyanim_clip_sample_model(b, f, q, n) == KEYANIM_OK &&
           memcmp(p, q, n * sizeof *p) == 0;
    same = same && keyanim_clip_sample_local(a, f, p, n) == KEYANIM_OK &&
           keyanim_clip_sample_local(b, f, q, n) == KEYANIM_OK && memcmp(p, q, n * sizeof *p) == 0;
    same = same && keyanim_clip_sample(a, f, u, c) == KEYANIM_OK && keyanim_clip_sample(b, f, v, c) == KEYANIM_OK &&
           memcmp(u, v, c * sizeof *u) == 0;
  }
  free(p);
  free(q);
  free(u);
  free(v);
  return same;
}

int main(int argc, char** argv) {
  size_t archive_size = 0, runtime_size = 0;
  uint8_t *archive, *runtime, *moved;
  keyanim_rig_cache* rigs = NULL;
  keyanim_clip *a = NULL, *viewed = NULL, *loaded = NULL, *shared = NULL, *none = NULL;
  if (argc != 3) {
    fprintf(stderr, "usage: view_test WALK.kanim WALK.runtime.kanim\n");
    return 2;
  }
  archive = read_file(argv[1], &archive_size);
  runtime = read_file(argv[2], &runtime_size);
  if (archive == NULL || runtime == NULL) {
    fprintf(stderr, "cannot read the clips\n");
    return 2;
  }
  CHECK(keyanim_clip_load(archive, archive_size, &a) == KEYANIM_OK);
  CHECK(keyanim_clip_view(runtime, runtime_size, NULL, NULL, &viewed) == KEYANIM_OK);
  CHECK(keyanim_clip_load(runtime, runtime_size, &loaded) == KEYANIM_OK);
  CHECK(keyanim_clip_runtime_profile(viewed) == 1 && keyanim_clip_runtime_profile(loaded) == 1);
  CHECK(keyanim_clip_runtime_profile(a) == 0 && keyanim_clip_runtime_profile(NULL) == 0);
  CHECK(keyanim_clip_format_version(viewed) == (5u << 16) && keyanim_clip_format_version(a) == (5u << 16));
  CHECK(same_poses(a, viewed));
  CHECK(same_poses(a, loaded));
  CHECK(keyanim_clip_total_keys(viewed) == keyanim_clip_total_keys(a));
  CHECK(keyanim_clip_check_content(viewed) == KEYANIM_OK && keyanim_clip_check_content(a) == KEYANIM_OK);
  CHECK(keyanim_clip_check_content(NULL) == KEYANIM_INVALID_ARGUMENT);

  /* Through a rig cache: the viewed clip shares the archive clip's skeleton. */
  CHECK(keyanim_rig_cache_create(&rigs) == KEYANIM_OK);
  keyanim_clip_free(a);
  CHECK(keyanim_clip_load_shared(archive, archive_size, NULL, rigs, &a) == KEYANIM_OK);
  CHECK(keyanim_clip_view(runtime, runtime_size, NULL, rigs, &shared) == KEYANIM_OK);
  CHECK(keyanim_clip_shares_rig(a, shared) == 1 && keyanim_rig_cache_rig_count(rigs) == 1);

  /* A misaligned address, a changed byte, NULL bytes: refused, nothing made. */
  moved = malloc(runtime_size + 8);
  if (moved != NULL) {
    memcpy(moved + 1, runtime, runtime_size);
    CHECK(keyanim_clip_view(moved + 1, runtime_size, NULL, NULL, &none) == KEYANIM_INVALID_ARGUMENT && none == NULL);
    memcpy(moved, runtime, runtime_size);
    moved[runtime_size / 2] ^= 0x20;
    CHECK(keyanim_clip_view(moved, runtime_size, NULL, NULL, &none) == KEYANIM_CHECKSUM_MISMATCH && none == NULL);
    free(moved);
  }
  CHECK(keyanim_clip_view(NULL, 5, NULL, NULL, &none) == KEYANIM_INVALID_ARGUMENT && none == NULL);

  /* An archive file through view() is decoded: it does not need the bytes afterwards. */
  {
    keyanim_clip* decoded = NULL;
    uint8_t* copy = malloc(archive_size);
    if (copy != NULL) {
      memcpy(copy, archive, archive_size);
      CHECK(keyanim_clip_view(copy, archive_size, NULL, NULL, &decoded) == KEYANIM_OK);
      memset(copy, 0, archive_size);
      free(copy);
      CHECK(decoded != NULL && same_poses(a, decoded));
      keyanim_clip_free(decoded);
    }
  }

  keyanim_clip_free(a);
  keyanim_clip_free(viewed);
  keyanim_clip_free(loaded);
  keyanim_clip_free(shared);
  keyanim_rig_cache_free(rigs);
  free(archive);
  free(runtime);
  if (failures) fprintf(stderr, "%d checks failed\n", failures);
  return failures ? 1 : 0;
}
