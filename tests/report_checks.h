// Two error reports are the same to the bit, field by field (doctest names the field that
// differs): for tests that compare a faster way of measuring with the plain one.
#pragma once
#include <doctest/doctest.h>

#include "keyanim/offline/metrics.h"

namespace keyanim::test {

inline void check_same_report(const offline::ErrorReport& got, const offline::ErrorReport& want) {
  CHECK(got.max_error == want.max_error);
  CHECK(got.rms_error == want.rms_error);
  CHECK(got.worst_joint == want.worst_joint);
  CHECK(got.worst_point == want.worst_point);
  CHECK(got.worst_frame == want.worst_frame);
  CHECK(got.worst_reading == want.worst_reading);
  CHECK(got.shell == want.shell);
  CHECK(got.both_readings == want.both_readings);
  CHECK(got.reading_max == want.reading_max);
  CHECK(got.joint_max == want.joint_max);
  CHECK(got.channel_max == want.channel_max);
}

}  // namespace keyanim::test
