/* Rig caches through the C API, from C99: rigs_test WALK.kanim HOP.kanim.
 * Two loads of the walk through one cache share one skeleton, the hop has its own; the hash is
 * the same with or without a cache; sharing changes no pose; freeing the clips empties the
 * cache; misuse is refused with its status. Exit 0, or 1 after listing the failed checks. */
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

static uint8_t* read_file(const char* path, size_t* size) {
  FILE* f = fopen(path, "rb");
  uint8_t* bytes = NULL;
  long n;
  if (f == NULL) return NULL;
  fseek(f, 0, SEEK_END);
  n = ftell(f);
  fseek(f, 0, SEEK_SET);
  if (n > 0) bytes = malloc((size_t)n);
  if (bytes != NULL && fread(bytes, 1, (size_t)n, f) != (size_t)n) {
    free(bytes);
    bytes = NULL;
  }
  fclose(f);
  *size = (size_t)n;
  return bytes;
}

/* Model poses of both clips at a few positions, bit for bit. */
static int same_poses(const keyanim_clip* a, const keyanim_clip* b) {
  uint32_t n = keyanim_clip_node_count(a);
  keyanim_transform* p = calloc(n, sizeof *p);
  keyanim_transform* q = calloc(n, sizeof *q);
  int same = p != NULL && q != NULL;
  double f;
  for (f = 0.0; same && f < keyanim_clip_frame_count(a); f += 7.3) {
    same = keyanim_clip_sample_model(a, f, p, n) == KEYANIM_OK && keyanim_clip_sample_model(b, f, q, n) == KEYANIM_OK &&
           memcmp(p, q, n * sizeof *p) == 0;
  }
  free(p);
  free(q);
  return same;
}

int main(int argc, char** argv) {
  size_t walk_size = 0, hop_size = 0;
  uint8_t *walk, *hop;
  keyanim_rig_cache* rigs = NULL;
  keyanim_clip *a = NULL, *b = NULL, *h = NULL, *alone = NULL, *none = NULL;
  if (argc != 3) return fprintf(stderr, "usage: rigs_test WALK.kanim HOP.kanim\n"), 2;
  walk = read_file(argv[1], &walk_size);
  hop = read_file(argv[2], &hop_size);
  if (walk == NULL || hop == NULL) return fprintf(stderr, "rigs_test: cannot read the clips\n"), 1;

  CHECK(keyanim_rig_cache_create(&rigs) == KEYANIM_OK && rigs != NULL);
  CHECK(keyanim_clip_load_shared(walk, walk_size, NULL, rigs, &a) == KEYANIM_OK);
  CHECK(keyanim_clip_load_shared(walk, walk_size, NULL, rigs, &b) == KEYANIM_OK);
  CHECK(keyanim_clip_load_shared(hop, hop_size, NULL, rigs, &h) == KEYANIM_OK);
  CHECK(keyanim_clip_load(walk, walk_size, &alone) == KEYANIM_OK);
  CHECK(keyanim_rig_cache_rig_count(rigs) == 2);
  CHECK(keyanim_clip_shares_rig(a, b) == 1);
  CHECK(keyanim_clip_shares_rig(a, h) == 0);
  CHECK(keyanim_clip_shares_rig(a, alone) == 0);
  CHECK(keyanim_clip_rig_hash(a) != 0 && keyanim_clip_rig_hash(a) == keyanim_clip_rig_hash(alone));
  CHECK(keyanim_clip_rig_hash(a) != keyanim_clip_rig_hash(h));
  CHECK(keyanim_clip_skeleton_bytes(a) == keyanim_clip_skeleton_bytes(alone));
  CHECK(same_poses(a, alone));

  /* Misuse: no cache, a NULL clip, a freed cache. */
  CHECK(keyanim_clip_load_shared(walk, walk_size, NULL, NULL, &none) == KEYANIM_INVALID_ARGUMENT && none == NULL);
  CHECK(keyanim_clip_load_shared(NULL, 5, NULL, rigs, &none) == KEYANIM_INVALID_ARGUMENT && none == NULL);
  CHECK(keyanim_clip_load_shared(walk, 10, NULL, rigs, &none) != KEYANIM_OK && none == NULL);  /* truncated */
  CHECK(keyanim_clip_rig_hash(NULL) == 0 && keyanim_last_error_status() == KEYANIM_INVALID_ARGUMENT);
  CHECK(keyanim_clip_shares_rig(a, NULL) == 0);
  CHECK(keyanim_rig_cache_rig_count(NULL) == 0);
  CHECK(keyanim_rig_cache_create(NULL) == KEYANIM_INVALID_ARGUMENT);

  /* The cache holds rigs weakly, and its clips outlive it. */
  keyanim_clip_free(b);
  keyanim_clip_free(h);
  CHECK(keyanim_rig_cache_rig_count(rigs) == 1);
  keyanim_rig_cache_free(rigs);
  keyanim_last_error_clear();
  keyanim_rig_cache_free(rigs); /* twice: refused, not undefined */
  CHECK(keyanim_last_error_status() == KEYANIM_INVALID_ARGUMENT);
  CHECK(keyanim_clip_load_shared(walk, walk_size, NULL, rigs, &none) == KEYANIM_INVALID_ARGUMENT);
  CHECK(same_poses(a, alone));
  keyanim_clip_free(a);
  keyanim_clip_free(alone);
  free(walk);
  free(hop);
  printf("rigs_test: %d failure(s)\n", failures);
  return failures == 0 ? 0 : 1;
}
