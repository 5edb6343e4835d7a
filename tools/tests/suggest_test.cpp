// "Did you mean": which names are near enough to suggest, and how the suggestion reads.
#include <doctest/doctest.h>

#include "suggest.h"

using keyanim::cli::did_you_mean;
using keyanim::cli::nearest_names;

TEST_CASE("near names: one edit for short words, up to three for long ones, swaps count once") {
  const std::vector<std::string> commands = {"encode", "decode", "info", "sample", "plot", "render", "eval", "verify"};
  CHECK(nearest_names("encod", commands) == std::vector<std::string>{"encode"});
  // A swap of neighbours is one edit: "encode" first, then "decode" (two edits, within the
  // bound of 2 for six letters).
  CHECK(nearest_names("ecnode", commands) == std::vector<std::string>{"encode", "decode"});
  CHECK(nearest_names("ENCODE", commands, 1) == std::vector<std::string>{"encode"});  // case is ignored
  CHECK(nearest_names("xyz", commands).empty());
  CHECK(nearest_names("vrfy", commands).empty());  // 2 edits in 4 letters: too far
  const std::vector<std::string> joints = {"LeftHand", "RightHand", "LeftHandIndex1", "LeftArm"};
  CHECK(nearest_names("LeftHnd", joints) == std::vector<std::string>{"LeftHand"});
  CHECK(nearest_names("lefthand", joints, 3) == std::vector<std::string>{"LeftHand"});
  CHECK(nearest_names("LeftHandIndx", joints, 3) == std::vector<std::string>{"LeftHandIndex1"});
  CHECK(nearest_names("RigtHand", joints, 3) == std::vector<std::string>{"RightHand"});  // LeftHand: 3 edits
  CHECK(nearest_names("LftArm", joints, 3) == std::vector<std::string>{"LeftArm"});
}

TEST_CASE("the suggestion's wording") {
  CHECK(did_you_mean("--eror", {"--error", "--shell"}) == " (did you mean '--error'?)");
  CHECK(did_you_mean("LeftHnd", {"LeftHand", "LeftHands"}, 3) == " (did you mean 'LeftHand' or 'LeftHands'?)");
  CHECK(did_you_mean("aaaa", {"aaab", "aaac", "aaad"}, 3) == " (did you mean 'aaab', 'aaac' or 'aaad'?)");
  CHECK(did_you_mean("--zzz", {"--error"}).empty());
}
