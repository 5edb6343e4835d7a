// The rate-distortion figure of `keyanim eval --svg`: compression ratio against error, log
// axes, one line per series (a file, or a key mode over every file).
#pragma once
#include <string>
#include <vector>

namespace keyanim::cli {

struct RdPoint {
  double error_percent = 0.0;  // max world-space error, percent of the skeleton size
  double ratio = 0.0;          // raw float32 bytes / .kanim bytes
};

struct RdSeries {
  std::string label;
  std::vector<RdPoint> points;  // drawn in order of error
};

// The SVG document: log-log axes fitted to the points (5% margins), with ticks at 1, 2 and 5
// times the powers of ten inside, labelled in plain numbers, axis labels with their units, each
// series a <path class="series rd"> with a circle (class "point") per point and a legend entry
// (a label over 60 characters shortened in its middle). The canvas widens for the legend and
// the subtitle. Points with a non-positive or non-finite value are left out (a log axis cannot
// show them). `subtitle` goes under the title.
std::string rd_plot(const std::vector<RdSeries>& series, const std::string& subtitle);

}  // namespace keyanim::cli
