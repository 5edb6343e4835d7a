/* keyanim.h's thread rules, from C99 with POSIX threads: threads_test CLIP.kanim.
 * Eight threads share one clip: each samples it at its own positions (plain and through a
 * cursor of its own) and must get what one thread got alone, bit for bit; each makes its own
 * mistake and must read back its own last error, untouched by the others' (thread-local). */
#define _POSIX_C_SOURCE 200809L
#include <keyanim.h>

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { kThreads = 8, kRounds = 3000, kMaxChannels = 1024 };

static const keyanim_clip* g_clip;
static uint32_t g_channels;
static float g_expected[kThreads][kMaxChannels];
static pthread_barrier_t g_start; /* all threads begin together, so that their calls interleave */

static double position(int thread) { return 3.0 + 7.25 * thread; }

static void* run(void* arg) {
  const int t = (int)(size_t)arg;
  float out[kMaxChannels], out2[kMaxChannels];
  keyanim_cursor* cursor = NULL;
  int r, bad = 0;
  char want[64];
  if (keyanim_cursor_create(g_clip, &cursor) != KEYANIM_OK) return (void*)1;
  pthread_barrier_wait(&g_start);
  for (r = 0; r < kRounds; ++r) {
    /* A mistake of this thread's own: a buffer t + 1 floats short. */
    if (keyanim_clip_sample(g_clip, position(t), out, g_channels - 1 - (uint32_t)t) != KEYANIM_OUTPUT_TOO_SMALL) bad = 1;
    snprintf(want, sizeof want, "out holds %u floats", g_channels - 1 - (unsigned)t);
    if (keyanim_clip_sample(g_clip, position(t), out, g_channels) != KEYANIM_OK) bad = 1;
    if (keyanim_cursor_sample(cursor, position(t) + 0.01 * r, out2, g_channels) != KEYANIM_OK) bad = 1;
    /* The last error is still this thread's (successes leave it; others' failures never reach it). */
    if (keyanim_last_error_status() != KEYANIM_OUTPUT_TOO_SMALL || strstr(keyanim_last_error_detail(), want) == NULL) bad = 1;
    if (memcmp(out, g_expected[t], sizeof(float) * g_channels) != 0) bad = 1;
  }
  keyanim_cursor_free(cursor);
  return (void*)(size_t)bad;
}

int main(int argc, char** argv) {
  keyanim_clip* clip = NULL;
  pthread_t threads[kThreads];
  int t, failures = 0;
  if (argc != 2 || keyanim_clip_load_file(argv[1], &clip) != KEYANIM_OK) {
    fprintf(stderr, "usage: threads_test CLIP.kanim (a loadable clip)\n");
    return 2;
  }
  g_clip = clip;
  g_channels = keyanim_clip_channel_count(clip);
  if (g_channels < kThreads + 1 || g_channels > kMaxChannels) return 2;
  for (t = 0; t < kThreads; ++t)
    if (keyanim_clip_sample(clip, position(t), g_expected[t], g_channels) != KEYANIM_OK) return 1;
  pthread_barrier_init(&g_start, NULL, kThreads);
  for (t = 0; t < kThreads; ++t) pthread_create(&threads[t], NULL, run, (void*)(size_t)t);
  for (t = 0; t < kThreads; ++t) {
    void* bad;
    pthread_join(threads[t], &bad);
    if (bad != NULL) {
      fprintf(stderr, "FAIL: thread %d saw another thread's values or last error\n", t);
      ++failures;
    }
  }
  keyanim_clip_free(clip);
  printf("threads_test: %d threads x %d rounds, %d failure(s)\n", kThreads, kRounds, failures);
  return failures == 0 ? 0 : 1;
}
