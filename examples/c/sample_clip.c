/* sample_clip: keyanim's C API from C99. Loads a .kanim file, prints its skeleton, then samples
 * it at each position given: Euler channels, local and model transforms.
 *
 *   sample_clip FILE.kanim POSITION...    POSITION: a frame position (12, 12.5), or a time in
 *                                         seconds prefixed with t (t0.4)
 *
 * Frame positions are sampled through a cursor (playback state, cheap when positions move
 * forward), times through the clip alone: both give the same values.
 * Output, one record a line (floats with 9 significant digits, enough to read them back
 * exactly; tests/capi/compare.py reads it):
 *   clip FRAMES FRAME_TIME NODES CHANNELS
 *   node INDEX PARENT END_SITE NAME
 *   at frame|time X
 *   channels V...
 *   local|model INDEX QX QY QZ QW TX TY TZ
 * Exit status: 0, or 1 with keyanim's error on standard error.
 */
#include <keyanim.h>

#include <stdio.h>
#include <stdlib.h>

/* Prints the calling thread's last keyanim error and returns 1. */
static int report(const char* what) {
  fprintf(stderr, "sample_clip: %s: %s (section '%s', byte %llu): %s\n", what,
          keyanim_status_name(keyanim_last_error_status()), keyanim_last_error_section(),
          (unsigned long long)keyanim_last_error_offset(), keyanim_last_error_detail());
  return 1;
}

static void print_transforms(const char* kind, const keyanim_transform* t, uint32_t count) {
  uint32_t i;
  for (i = 0; i < count; ++i)
    printf("%s %u %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", kind, i, t[i].rotation[0], t[i].rotation[1],
           t[i].rotation[2], t[i].rotation[3], t[i].translation[0], t[i].translation[1], t[i].translation[2]);
}

/* One position: `x` is a frame position, or seconds if is_time. */
static int sample_at(const keyanim_clip* clip, keyanim_cursor* cursor, double x, int is_time, float* channels,
                     keyanim_transform* pose) {
  const uint32_t nc = keyanim_clip_channel_count(clip), nn = keyanim_clip_node_count(clip);
  uint32_t i;
  printf("at %s %.17g\n", is_time ? "time" : "frame", x);
  if ((is_time ? keyanim_clip_sample_time(clip, x, channels, nc) : keyanim_cursor_sample(cursor, x, channels, nc)) !=
      KEYANIM_OK)
    return report("sample");
  printf("channels");
  for (i = 0; i < nc; ++i) printf(" %.9g", channels[i]);
  printf("\n");
  if ((is_time ? keyanim_clip_sample_local_time(clip, x, pose, nn) : keyanim_cursor_sample_local(cursor, x, pose, nn)) !=
      KEYANIM_OK)
    return report("sample_local");
  print_transforms("local", pose, nn);
  if ((is_time ? keyanim_clip_sample_model_time(clip, x, pose, nn) : keyanim_cursor_sample_model(cursor, x, pose, nn)) !=
      KEYANIM_OK)
    return report("sample_model");
  print_transforms("model", pose, nn);
  return 0;
}

int main(int argc, char** argv) {
  keyanim_clip* clip = NULL;
  keyanim_cursor* cursor = NULL;
  float* channels;
  keyanim_transform* pose;
  uint32_t i, nodes;
  int a, status = 0;
  if (argc < 2) {
    fprintf(stderr, "usage: sample_clip FILE.kanim POSITION...\n");
    return 2;
  }
  if (keyanim_clip_load_file(argv[1], &clip) != KEYANIM_OK) return report(argv[1]);
  if (keyanim_cursor_create(clip, &cursor) != KEYANIM_OK) {
    keyanim_clip_free(clip);
    return report("cursor");
  }
  nodes = keyanim_clip_node_count(clip);
  printf("clip %u %.17g %u %u\n", keyanim_clip_frame_count(clip), keyanim_clip_frame_time(clip), nodes,
         keyanim_clip_channel_count(clip));
  for (i = 0; i < nodes; ++i)
    printf("node %u %d %d %s\n", i, keyanim_clip_node_parent(clip, i),
           keyanim_skeleton_node_is_end_site(keyanim_clip_skeleton(clip), i), keyanim_clip_node_name(clip, i));

  /* One buffer of each kind, sized once: sampling itself never allocates. */
  channels = malloc(sizeof(float) * (keyanim_clip_channel_count(clip) + 1));
  pose = malloc(sizeof(keyanim_transform) * (nodes + 1));
  if (channels == NULL || pose == NULL) status = 1;
  for (a = 2; a < argc && status == 0; ++a) {
    const int is_time = argv[a][0] == 't';
    status = sample_at(clip, cursor, atof(argv[a] + is_time), is_time, channels, pose);
  }
  free(channels);
  free(pose);
  keyanim_cursor_free(cursor);
  keyanim_clip_free(clip);
  return status;
}
