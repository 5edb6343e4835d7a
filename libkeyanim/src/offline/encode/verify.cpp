#include "offline/encode/verify.h"

#include <algorithm>
#include <cmath>
#include <new>
#include <span>

#include "keyanim/offline/container.h"
#include "keyanim/offline/decode.h"
#include "keyanim/offline/metrics.h"
#include "offline/encode/channel_fit.h"
#include "offline/encode/rotations.h"
#include "offline/encode/spare.h"
#include "offline/parallel.h"

namespace keyanim::offline {
namespace {

Key key_at(const EncodedChannel& ch, size_t i) { return {ch.frames[i], dequantize(ch.q[i], ch.step)}; }

// Frame of the key `back` keys before index i (0 past the start), and `ahead` keys after
// index i (the last frame past the end).
uint32_t frame_before(const EncodedChannel& ch, size_t i, size_t back) {
  return i >= back ? ch.frames[i - back] : 0;
}
uint32_t frame_after(const EncodedChannel& ch, size_t i, size_t ahead, uint32_t last) {
  return i + ahead < ch.frames.size() ? ch.frames[i + ahead] : last;
}

bool same_curve_kind(const EncodedChannel& a, const EncodedChannel& b) {
  return a.interp == b.interp && (a.interp == Interpolation::linear || tension_to_s(a.tension) == tension_to_s(b.tension));
}

}  // namespace

void ChannelCursor::prepare() {
  const EncodedChannel& ch = *ch_;
  const size_t j = j_, n = ch.frames.size();
  const Key before = j > 0 ? key_at(ch, j - 1) : Key{}, after = j + 2 < n ? key_at(ch, j + 2) : Key{};
  ops_ = window_operands(j > 0 ? &before : nullptr, key_at(ch, j), key_at(ch, j + 1), j + 2 < n ? &after : nullptr,
                         ch.interp, tension_to_s(ch.tension), rule_);
  prepared_ = j;
}

void decode_channel_at(const EncodedChannel& ch, TangentRule rule, const uint32_t* frames, size_t count, double* out,
                       size_t stride) {
  ChannelCursor cursor(ch, rule);
  for (size_t i = 0; i < count; ++i) out[i * stride] = cursor.at(frames[i]);
}

void changed_ranges(const EncodedChannel& a, const EncodedChannel& b, uint32_t frame_count,
                    std::vector<std::pair<uint32_t, uint32_t>>& out) {
  out.clear();
  if (frame_count == 0) return;
  const uint32_t last = frame_count - 1;
  const size_t na = a.frames.size(), nb = b.frames.size();
  if (!same_curve_kind(a, b) && (na > 1 || nb > 1)) return out.push_back({0, last});
  uint32_t marked = 0;  // frames below this are already in `out`
  auto mark = [&](uint32_t lo, uint32_t hi) {
    lo = std::max(lo, marked);
    if (lo > hi) return;
    if (!out.empty() && lo <= out.back().second + 1) out.back().second = hi;
    else out.push_back({lo, hi});
    marked = hi + 1;
  };
  // Keys both lists share at the start and at the end (the same frame and value) change
  // nothing; only the keys between them are merged. A refit usually moves a few keys.
  size_t same_front = 0, same_back = 0;
  if (a.step == b.step) {
    const size_t common = std::min(na, nb);
    auto same = [&](size_t ka, size_t kb) { return a.frames[ka] == b.frames[kb] && a.q[ka] == b.q[kb]; };
    while (same_front < common && same(same_front, same_front)) ++same_front;
    while (same_front + same_back < common && same(na - 1 - same_back, nb - 1 - same_back)) ++same_back;
  }
  size_t i = same_front, j = same_front;  // merge the rest of both key lists by frame
  while (i < na - same_back || j < nb - same_back) {
    const uint32_t fa = i < na ? a.frames[i] : UINT32_MAX, fb = j < nb ? b.frames[j] : UINT32_MAX;
    const uint32_t g = std::min(fa, fb);
    const bool in_a = fa == g, in_b = fb == g;
    const bool differs = !(in_a && in_b) || dequantize(a.q[i], a.step) != dequantize(b.q[j], b.step);
    if (differs) {
      // Keys strictly before g are a[0..i) and b[0..j); strictly after, from i (+1 if g is in a).
      const uint32_t lo = std::min(frame_before(a, i, 2), frame_before(b, j, 2));
      const uint32_t hi = std::max(frame_after(a, i + (in_a ? 1 : 0), 1, last), frame_after(b, j + (in_b ? 1 : 0), 1, last));
      mark(lo, hi);  // 0 and the last frame when g is near an end: the clamped values
    }
    i += in_a, j += in_b;
  }
}

FrameMarks::FrameMarks(uint32_t frames, size_t nodes)
    : words_((size_t(frames) + 63) / 64), check_(frames, 0), moved_(nodes * words_, 0), over_(nodes * words_, 0) {}

void FrameMarks::mark(uint32_t node, uint32_t first, uint32_t last) {
  for (uint32_t f = first; f <= last; ++f) check_[f] |= kChanged;
  uint64_t* bits = moved_.data() + node * words_;
  for (uint32_t f = first; f <= last;) {
    if (f % 64 == 0 && last - f >= 63) {
      bits[f / 64] = ~uint64_t(0);
      f += 64;
    } else {
      bits[f / 64] |= uint64_t(1) << (f % 64);
      ++f;
    }
  }
}

void FrameMarks::clear_moved() { std::fill(moved_.begin(), moved_.end(), 0); }

namespace {

// Marks in w.measure[k] the nodes to measure at frame f (nonzero): all of them (kAll), or the
// nodes that were over and the subtrees of the nodes that moved (kSubtree: a node's value
// depends on its ancestors'); adds them to w.pose.
constexpr uint8_t kMeasure = 1, kSubtree = 2;
void select_nodes(const Skeleton& s, const FrameMarks& marks, uint8_t check, uint32_t f, size_t k, VerifyScratch& w) {
  const bool all = check & FrameMarks::kAll, any_over = check & FrameMarks::kOver;
  uint8_t* measure = w.measure[k].data();
  for (size_t j = 0; j < s.joints.size(); ++j) {
    const int32_t p = s.joints[j].parent;
    const bool subtree = marks.moved(uint32_t(j), f) || (p >= 0 && size_t(p) < j && (measure[size_t(p)] & kSubtree));
    measure[j] = subtree ? kSubtree | kMeasure : all || (any_over && marks.over(uint32_t(j), f)) ? kMeasure : 0;
    w.pose[j] |= measure[j];
    w.error[k][j] = 0.0, w.shell_over[k][j] = 0;
  }
}

// Largest distance per measured node between the original's points and the decoded's, into
// w.error[k] (the formula of measure_error, so that what passes here passes the final report;
// the square is compared first against a bound safely inside the tolerance: sqrt is correctly
// rounded).
void add_errors(const Skeleton& s, double tol, double shell, const Vec3* original, const Vec3* decoded, size_t k,
                VerifyScratch& w) {
  const double surely_within = tol * tol * (1.0 - 1e-9);
  for (size_t d = 0; d < s.joints.size(); ++d) {
    if (!w.measure[k][d]) continue;
    const size_t first_point = d * kPointsPerNode;
    const size_t points = measured_point_count(s.joints[d], shell);
    for (size_t p = first_point; p < first_point + points; ++p) {
      const Vec3& a = original[p];
      const Vec3& b = decoded[p];
      const double dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2];
      const double sq = dx * dx + dy * dy + dz * dz;
      if (sq <= surely_within) continue;
      const double pe = std::isnan(sq) ? HUGE_VAL : std::sqrt(sq);  // a NaN is over, and stays the worst
      w.error[k][d] = std::max(w.error[k][d], pe);
      if (p > first_point && pe > tol) w.shell_over[k][d] = 1;
    }
  }
}

// Four rows at a time: `rows` posed under readings[0] (and the add reading when both are
// measured) into w.points (w.points_add), for the nodes w.pose marks. `quats`: rows of stored
// values with quaternion nodes.
void pose_rows(const Skeleton& s, const std::array<const double*, 4>& rows, double shell,
               std::span<const PositionReading> readings, VerifyScratch& w, const QuatForms* quats = nullptr) {
  measured_points(s, rows, shell, readings[0], w.points, w.pose.data(), readings.size() > 1 ? &w.points_add : nullptr,
                  quats);
}

}  // namespace

OriginalPoints::OriginalPoints(const Motion& m, double shell, size_t budget, unsigned threads) : budget_(budget) {
  const std::span<const PositionReading> readings = measured_readings(m.skeleton);
  const size_t per_frame = size_t(kPointsPerNode) * m.skeleton.joints.size();
  if (m.frame_count == 0 || per_frame == 0 ||
      size_t(m.frame_count) * per_frame * sizeof(Vec3) * readings.size() > budget) {
    drop_spare<Vec3>();
    return;
  }
  points_ = take_spare<Vec3>();
  points_.resize(readings.size() * size_t(m.frame_count) * per_frame);
  per_frame_ = per_frame, frames_ = m.frame_count;
  const size_t n_ch = m.channel_count();
  constexpr uint32_t kGroups = 64;  // frames per job: 16 groups of four
  parallel_for((size_t(m.frame_count) + kGroups - 1) / kGroups, threads, [&](size_t job, unsigned) {
    VerifyScratch w;
    w.pose.assign(m.skeleton.joints.size(), 1);
    const uint32_t end = uint32_t(std::min<size_t>(m.frame_count, (job + 1) * kGroups));
    for (uint32_t f = uint32_t(job * kGroups); f < end; f += 4) {
      std::array<const double*, 4> rows;
      for (uint32_t k = 0; k < 4; ++k) rows[k] = m.values.data() + size_t(std::min(f + k, end - 1)) * n_ch;
      pose_rows(m.skeleton, rows, shell, readings, w);
      for (uint32_t k = 0; k < 4 && f + k < end; ++k)
        for (size_t r = 0; r < readings.size(); ++r) {
          const std::vector<Vec3>& from = r == 0 ? w.points[k] : w.points_add[k];
          std::copy(from.begin(), from.end(), points_.begin() + ptrdiff_t((r * frames_ + f + k) * per_frame));
        }
    }
  });
}

OriginalPoints::~OriginalPoints() { give_spare(std::move(points_), budget_); }

void verify_window(const Motion& m, const std::vector<EncodedChannel>& channels, TangentRule rule, double tolerance,
                   double shell, uint32_t first, uint32_t count, FrameMarks& marks, std::vector<OverNode>& over,
                   VerifyScratch& w, const OriginalPoints* originals, const QuatForms* quats) {
  const double tol = quats ? tolerance * (1.0 - kQuatMargin) : tolerance;
  uint8_t* check = marks.check();
  const auto& joints = m.skeleton.joints;
  const size_t n_ch = channels.size(), nodes = joints.size();
  const std::span<const PositionReading> readings = measured_readings(m.skeleton);
  const bool held = originals && !originals->empty();
  w.cursors.resize(n_ch);
  for (size_t c = 0; c < n_ch; ++c) w.cursors[c] = ChannelCursor(channels[c], rule);
  w.frames.clear();
  for (uint32_t f = first; f < first + count; ++f)
    if (check[f]) w.frames.push_back(f);
  for (size_t k = 0; k < 4; ++k) {
    w.row[k].resize(n_ch), w.measure[k].resize(nodes), w.error[k].resize(nodes), w.shell_over[k].resize(nodes);
  }
  w.pose.resize(nodes);
  // Frames in groups: one FK pass of four rows poses two frames' original and decoded rows, or
  // four frames' decoded rows when the original's points are held. A group short of frames
  // repeats its last rows (posed, not measured).
  const size_t group = held ? 4 : 2;
  for (size_t i = 0; i < w.frames.size(); i += group) {
    const size_t size = std::min(group, w.frames.size() - i);
    std::fill(w.pose.begin(), w.pose.end(), 0);
    for (size_t k = 0; k < size; ++k) select_nodes(m.skeleton, marks, check[w.frames[i + k]], w.frames[i + k], k, w);
    for (size_t j = nodes; j-- > 0;) {  // and their ancestors
      const int32_t p = joints[j].parent;
      if (w.pose[j] && p >= 0 && size_t(p) < j) w.pose[size_t(p)] = 1;
    }
    for (size_t k = 0; k < size; ++k) {
      const uint32_t f = w.frames[i + k];
      for (size_t j = 0; j < nodes; ++j) {
        if (!w.pose[j]) continue;
        for (size_t c = joints[j].first_channel; c < joints[j].first_channel + joints[j].channels.size(); ++c)
          w.row[k][c] = w.cursors[c].at(f);
      }
    }
    // The original's row; with quaternion nodes, in the same stored form as the decoded rows
    // (their rotation channels hold x, y, z of the original's relative rotation), so that one
    // FK pass poses both.
    auto original = [&](size_t k) -> const double* {
      const uint32_t f = w.frames[i + std::min(k, size - 1)];
      if (!quats) return m.values.data() + size_t(f) * n_ch;
      w.original[k].resize(n_ch);
      stored_row(m, *quats, f, w.original[k].data());
      return w.original[k].data();
    };
    auto decoded = [&](size_t k) -> const double* { return w.row[std::min(k, size - 1)].data(); };
    if (held)
      pose_rows(m.skeleton, {decoded(0), decoded(1), decoded(2), decoded(3)}, shell, readings, w, quats);
    else
      pose_rows(m.skeleton, {original(0), decoded(0), original(1), decoded(1)}, shell, readings, w, quats);
    for (size_t r = 0; r < readings.size(); ++r) {
      const auto& points = r == 0 ? w.points : w.points_add;
      for (size_t k = 0; k < size; ++k) {
        const Vec3* a = held ? originals->at(w.frames[i + k], r) : points[2 * k].data();
        const Vec3* b = held ? points[k].data() : points[2 * k + 1].data();
        add_errors(m.skeleton, tol, shell, a, b, k, w);
      }
    }
    for (size_t k = 0; k < size; ++k) {
      const uint32_t f = w.frames[i + k];
      bool frame_over = false;
      for (size_t d = 0; d < nodes; ++d) {
        if (!w.measure[k][d]) continue;
        marks.set_over(uint32_t(d), f, w.error[k][d] > tol);
        if (w.error[k][d] <= tol) continue;
        over.push_back({f, uint32_t(d) & 0x7FFFFFFFu, w.shell_over[k][d] != 0u, w.error[k][d]});  // nodes < 2^31
        frame_over = true;
      }
      check[f] = frame_over ? FrameMarks::kOver : 0;
    }
  }
}

ErrorReport measure_encoded(const Motion& m, const EncodedClip& enc, double shell, unsigned threads) {
  const Clip clip = to_clip(enc);
  const uint32_t frames = m.frame_count, n_ch = m.channel_count();
  const uint32_t window = measure_window(frames);
  const size_t windows = (size_t(frames) + window - 1) / window;
  // The clip's skeleton is the motion's (encode copies it): one skeleton poses both.
  std::vector<ErrorAccumulator> parts(windows, ErrorAccumulator(m.skeleton, shell));
  parallel_for(windows, threads, [&](size_t w, unsigned) {
    const uint32_t end = uint32_t(std::min<size_t>(frames, (w + 1) * window));
    uint32_t f = uint32_t(w * window);
    FrameDecoder decoder;  // the window's frames, as decode_motion makes them
    ResampleOptions range;
    range.first_frame = f, range.last_frame = end - 1;
    decoder.start(clip, range);
    const uint32_t start = f;
    std::array<std::vector<double>, 2> decoded{std::vector<double>(n_ch), std::vector<double>(n_ch)};
    auto decode = [&](uint32_t g, std::vector<double>& out) {
      decoder.frame(g - start, out);
      return out.data();
    };
    auto original = [&](uint32_t g) { return m.values.data() + size_t(g) * n_ch; };
    for (; f + 1 < end; f += 2) {  // two frames at a time: one FK poses four rows
      const double* a = decode(f, decoded[0]);
      parts[w].add_frames(f, {original(f), a, original(f + 1), decode(f + 1, decoded[1])});
    }
    if (f < end) parts[w].add_frame(f, original(f), decode(f, decoded[0]));
  });
  ErrorAccumulator total(m.skeleton, shell);
  for (const ErrorAccumulator& p : parts) total.merge(p);
  return total.report(frames);
}

}  // namespace keyanim::offline
