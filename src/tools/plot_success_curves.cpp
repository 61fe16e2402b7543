/// \file plot_success_curves.cpp
/// Draws success curves (success rate in percent vs error threshold k, the paper's Sec. 4.1
/// and OPT's plots) into a PNG with OpenCV (no plotting library is available in Debian's base
/// set without extra packages). Each curve is a file of normalized errors delta_i / d, one a
/// line; the legend shows each curve's AUC (0..20 for k in [0, 0.2]).
///
/// Usage: plot_success_curves --output FILE.png [--title TEXT] [--k-max K=0.2]
///                            --curve LABEL FILE [--curve LABEL FILE ...]

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "klt_contour_tracker/core/metrics.h"

namespace {

struct Curve {
  std::string label;
  std::vector<double> errors;  ///< delta / diameter
};

std::vector<double> read_errors(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::vector<double> values;
  double v;
  while (in >> v) values.push_back(v);
  if (!in.eof()) throw std::runtime_error(path + ": not a list of numbers");
  return values;
}

cv::Scalar palette(int i) {
  static const cv::Scalar colors[] = {{180, 119, 31}, {14, 127, 255}, {44, 160, 44}, {40, 39, 214},
                                      {189, 103, 148}, {75, 86, 140}, {194, 119, 227}, {127, 127, 127},
                                      {34, 189, 188}, {207, 190, 23}};
  return colors[i % 10];
}

void plot(const std::vector<Curve>& curves, const std::string& title, double k_max, const std::string& output) {
  const int width = 760, height = 460, left = 60, right = 250, top = 36, bottom = 48;
  const int pw = width - left - right, ph = height - top - bottom;
  cv::Mat img(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  auto to_px = [&](double k, double success) {
    return cv::Point(left + static_cast<int>(pw * k / k_max + 0.5),
                     top + ph - static_cast<int>(ph * success / 100.0 + 0.5));
  };
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  for (int i = 0; i <= 10; ++i) {
    const double s = 10.0 * i;
    cv::line(img, to_px(0, s), to_px(k_max, s), cv::Scalar(225, 225, 225), 1);
    if (i % 2 == 0)
      cv::putText(img, std::to_string(static_cast<int>(s)), to_px(0, s) + cv::Point(-32, 4), font, 0.4,
                  cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  for (int i = 0; i <= 4; ++i) {
    const double k = k_max * i / 4;
    cv::line(img, to_px(k, 0), to_px(k, 100), cv::Scalar(225, 225, 225), 1);
    char text[16];
    std::snprintf(text, sizeof(text), "%.2f", k);
    cv::putText(img, text, to_px(k, 0) + cv::Point(-14, 18), font, 0.4, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  cv::rectangle(img, to_px(0, 100), to_px(k_max, 0), cv::Scalar(0, 0, 0), 1);
  cv::putText(img, "error threshold k (fraction of the object diameter)", cv::Point(left + 40, height - 10),
              font, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  cv::putText(img, "success %", cv::Point(4, top - 12), font, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  cv::putText(img, title, cv::Point(left + 60, 22), font, 0.55, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);

  const int samples = 200;
  for (std::size_t c = 0; c < curves.size(); ++c) {
    std::vector<cv::Point> points;
    for (int i = 0; i <= samples; ++i) {
      const double k = k_max * i / samples;
      points.push_back(to_px(k, 100.0 * kct::success_rate(curves[c].errors, 1.0, k)));
    }
    cv::polylines(img, points, false, palette(static_cast<int>(c)), 2, cv::LINE_AA);
    char legend[96];
    std::snprintf(legend, sizeof(legend), "%s (%.1f)", curves[c].label.c_str(),
                  kct::auc_score(curves[c].errors, 1.0, k_max));
    const cv::Point at(width - right + 12, top + 14 + 20 * static_cast<int>(c));
    cv::line(img, at + cv::Point(0, -4), at + cv::Point(18, -4), palette(static_cast<int>(c)), 3);
    cv::putText(img, legend, at + cv::Point(24, 0), font, 0.42, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  cv::putText(img, "label (AUC of 20)", cv::Point(width - right + 12, top - 6), font, 0.4,
              cv::Scalar(80, 80, 80), 1, cv::LINE_AA);
  if (!cv::imwrite(output, img, {cv::IMWRITE_PNG_COMPRESSION, 9}))
    throw std::runtime_error("cannot write " + output);
}

}  // namespace

int main(int argc, char** argv) {
  const char* usage =
      "usage: plot_success_curves --output FILE.png [--title TEXT] [--k-max K]"
      " --curve LABEL ERRORS_FILE [--curve ...]\n"
      "  ERRORS_FILE: normalized errors delta_i / diameter, one a line\n";
  try {
    std::string output, title;
    double k_max = 0.2;
    std::vector<Curve> curves;
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      auto next = [&]() -> std::string {
        if (i + 1 >= argc) throw std::invalid_argument("missing value after " + arg);
        return argv[++i];
      };
      if (arg == "--help" || arg == "-h") {
        std::cout << usage;
        return 0;
      } else if (arg == "--output") output = next();
      else if (arg == "--title") title = next();
      else if (arg == "--k-max") k_max = std::stod(next());
      else if (arg == "--curve") {
        Curve curve;
        curve.label = next();
        curve.errors = read_errors(next());
        curves.push_back(std::move(curve));
      } else throw std::invalid_argument("unknown option " + arg);
    }
    if (output.empty() || curves.empty()) throw std::invalid_argument("--output and a --curve are required");
    if (!(k_max > 0.0)) throw std::invalid_argument("--k-max must be > 0");
    plot(curves, title, k_max, output);
  } catch (const std::exception& e) {
    std::cerr << "plot_success_curves: " << e.what() << "\n" << usage;
    return 1;
  }
  return 0;
}
