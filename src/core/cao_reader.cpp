#include "klt_contour_tracker/core/cao_reader.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

namespace kct {
namespace {

constexpr int kMaxIncludeDepth = 16;
constexpr long kMaxCount = 10000000;  // points / faces per section: beyond is a corrupt count

std::string truncated(const std::string& text) {
  return text.size() <= 60 ? text : text.substr(0, 57) + "...";
}

std::string parent_folder(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
}

/// Both paths name the same existing file (compared after resolving links and `..`).
bool same_file(const std::string& a, const std::string& b) {
  char* ra = ::realpath(a.c_str(), nullptr);
  char* rb = ::realpath(b.c_str(), nullptr);
  const bool same = ra && rb ? std::string(ra) == rb : a == b;
  std::free(ra);
  std::free(rb);
  return same;
}

/// One non-empty line with its comment removed.
struct CaoLine {
  int number;  // 1-based line number in the file
  std::string text;
  std::vector<std::string> tokens;
};

/// The file's lines: `#` comments stripped, CR removed (CRLF files), empty lines dropped.
class CaoLines {
 public:
  CaoLines(const std::string& path) : path_(path) {
    std::ifstream file(path, std::ios::binary);
    if (!file) throw std::runtime_error("read_cao('" + path + "'): file not found or not readable");
    std::string raw;
    int number = 0;
    while (std::getline(file, raw)) {
      ++number;
      const auto hash = raw.find('#');
      if (hash != std::string::npos) raw.erase(hash);
      for (char& c : raw)
        if (c == '\r' || c == '\t') c = ' ';
      std::istringstream words(raw);
      CaoLine line{number, raw, {}};
      for (std::string w; words >> w;) line.tokens.push_back(w);
      if (!line.tokens.empty()) lines_.push_back(std::move(line));
    }
  }

  bool done() const { return next_ >= lines_.size(); }
  const CaoLine& peek() const { return lines_[next_]; }
  const CaoLine& take(const std::string& what) {
    if (done()) throw error_at_end("expected " + what);
    return lines_[next_++];
  }
  std::runtime_error error(const CaoLine& line, const std::string& reason) const {
    return std::runtime_error("read_cao('" + path_ + "'): line " + std::to_string(line.number) +
                              ": " + reason + " (line: '" + truncated(line.text) + "')");
  }
  std::runtime_error error_at_end(const std::string& reason) const {
    return std::runtime_error("read_cao('" + path_ + "'): end of file: " + reason);
  }

 private:
  std::string path_;
  std::vector<CaoLine> lines_;
  std::size_t next_ = 0;
};

bool parse_long(const std::string& token, long& value) {
  errno = 0;
  char* end = nullptr;
  value = std::strtol(token.c_str(), &end, 10);
  return errno == 0 && end != token.c_str() && *end == '\0';
}

bool parse_double(const std::string& token, double& value) {
  errno = 0;
  char* end = nullptr;
  value = std::strtod(token.c_str(), &end);
  return errno == 0 && end != token.c_str() && *end == '\0' && std::isfinite(value);
}

/// The count line of a section: a single non-negative integer first on its line.
long read_count(CaoLines& lines, const std::string& section) {
  const CaoLine& line = lines.take("the number of " + section);
  long count = 0;
  if (!parse_long(line.tokens[0], count) || count < 0 || count > kMaxCount)
    throw lines.error(line, "expected the number of " + section + " (an integer in [0, " +
                                std::to_string(kMaxCount) + "]), got '" +
                                truncated(line.tokens[0]) + "'");
  return count;
}

/// Index token `k` of `line`, checked against [0, size).
int read_index(CaoLines& lines, const CaoLine& line, std::size_t k, long size,
               const std::string& what) {
  long value = 0;
  if (k >= line.tokens.size())
    throw lines.error(line, "expected " + what + " index number " + std::to_string(k));
  if (!parse_long(line.tokens[k], value) || value < 0 || value >= size)
    throw lines.error(line, what + " index '" + truncated(line.tokens[k]) + "' is not in [0, " +
                                std::to_string(size) + ")");
  return static_cast<int>(value);
}

double read_number(CaoLines& lines, const CaoLine& line, std::size_t k, const std::string& what) {
  double value = 0.0;
  if (k >= line.tokens.size()) throw lines.error(line, "expected " + what);
  if (!parse_double(line.tokens[k], value))
    throw lines.error(line, what + ": '" + truncated(line.tokens[k]) + "' is not a finite number");
  return value;
}

/// An orthonormal pair spanning the plane orthogonal to the unit vector `axis`.
void plane_basis(const Eigen::Vector3d& axis, Eigen::Vector3d& u, Eigen::Vector3d& v) {
  u = axis.unitOrthogonal();
  v = axis.cross(u);
}

void read_file(const std::string& path, int curve_segments, int depth,
               std::vector<std::string>& stack, CaoModel& model);

void read_includes(CaoLines& lines, const std::string& path, int curve_segments, int depth,
                   std::vector<std::string>& stack, CaoModel& model) {
  while (!lines.done() && lines.peek().text.find("load(") != std::string::npos) {
    const CaoLine& line = lines.take("load(...)");
    const auto open = line.text.find('"'), close = line.text.rfind('"');
    if (open == std::string::npos || close <= open + 1)
      throw lines.error(line, "expected load(\"file.cao\") with the file name in double quotes");
    std::string included = line.text.substr(open + 1, close - open - 1);
    if (included[0] != '/') included = parent_folder(path) + "/" + included;
    if (depth + 1 > kMaxIncludeDepth)
      throw lines.error(line, "load() nested deeper than " + std::to_string(kMaxIncludeDepth));
    for (const std::string& open_file : stack)
      if (same_file(open_file, included))
        throw lines.error(line, "load() cycle: '" + truncated(included) + "' includes itself");
    read_file(included, curve_segments, depth + 1, stack, model);
  }
}

void read_file(const std::string& path, int curve_segments, int depth,
               std::vector<std::string>& stack, CaoModel& model) {
  CaoLines lines(path);
  stack.push_back(path);
  if (!lines.done() && (lines.peek().tokens[0] == "V1" || lines.peek().tokens[0] == "v1"))
    lines.take("V1");
  read_includes(lines, path, curve_segments, depth, stack, model);
  if (lines.done()) {  // a file of load() lines only
    stack.pop_back();
    return;
  }

  const int base = static_cast<int>(model.points.size());
  const long num_points = read_count(lines, "points");
  for (long i = 0; i < num_points; ++i) {
    const CaoLine& line = lines.take("point " + std::to_string(i) + " (x y z)");
    Eigen::Vector3d p;
    for (int k = 0; k < 3; ++k) p[k] = read_number(lines, line, k, "point coordinate");
    model.points.push_back(p);
  }

  const long num_lines = read_count(lines, "3D lines");
  std::vector<std::pair<int, int>> segments;
  for (long i = 0; i < num_lines; ++i) {
    const CaoLine& line = lines.take("3D line " + std::to_string(i) + " (two point indices)");
    segments.emplace_back(read_index(lines, line, 0, num_points, "point"),
                          read_index(lines, line, 1, num_points, "point"));
  }

  const long num_line_faces = read_count(lines, "faces from lines");
  for (long i = 0; i < num_line_faces; ++i) {
    const CaoLine& line = lines.take("face from lines " + std::to_string(i));
    long n = 0;
    if (!parse_long(line.tokens[0], n) || n < 3 || n > kMaxCount)
      throw lines.error(line,
                        "a face needs a line count >= 3, got '" + truncated(line.tokens[0]) + "'");
    // Chain the lines into a loop: each line must share an end point with the previous one.
    std::vector<int> loop;
    for (long k = 0; k < n; ++k) {
      const auto& s = segments[read_index(lines, line, 1 + k, num_lines, "line")];
      if (k == 0) {
        loop = {s.first, s.second};
        continue;
      }
      if (k == 1 && (s.first == loop[0] || s.second == loop[0]) && s.first != loop[1] &&
          s.second != loop[1])
        std::swap(loop[0], loop[1]);  // the first line was listed against the loop's direction
      if (s.first == loop.back())
        loop.push_back(s.second);
      else if (s.second == loop.back())
        loop.push_back(s.first);
      else
        throw lines.error(line, "line " + line.tokens[1 + k] +
                                    " does not continue the previous line's end point");
    }
    if (loop.front() != loop.back())
      throw lines.error(line, "the face's lines do not form a closed loop");
    loop.pop_back();
    for (int& idx : loop) idx += base;
    model.polygons.push_back(loop);
  }

  const long num_point_faces = read_count(lines, "faces from points");
  for (long i = 0; i < num_point_faces; ++i) {
    const CaoLine& line = lines.take("face from points " + std::to_string(i));
    long n = 0;
    if (!parse_long(line.tokens[0], n) || n < 3 || n > kMaxCount)
      throw lines.error(line,
                        "a face needs a point count >= 3, got '" + truncated(line.tokens[0]) + "'");
    std::vector<int> polygon;
    for (long k = 0; k < n; ++k)
      polygon.push_back(base + read_index(lines, line, 1 + k, num_points, "point"));
    model.polygons.push_back(polygon);
  }

  if (!lines.done()) {  // cylinders: an open tube between the planes through the axis points
    const long num_cylinders = read_count(lines, "cylinders");
    for (long i = 0; i < num_cylinders; ++i) {
      const CaoLine& line = lines.take("cylinder " + std::to_string(i) + " (i j radius)");
      const Eigen::Vector3d a =
          model.points[base + read_index(lines, line, 0, num_points, "point")];
      const Eigen::Vector3d b =
          model.points[base + read_index(lines, line, 1, num_points, "point")];
      const double radius = read_number(lines, line, 2, "cylinder radius");
      if (!(radius > 0.0) || !((b - a).norm() > 0.0))
        throw lines.error(line, "a cylinder needs a radius > 0 and two distinct axis points");
      Eigen::Vector3d u, v;
      plane_basis((b - a).normalized(), u, v);
      const int first = static_cast<int>(model.points.size());
      for (int k = 0; k < curve_segments; ++k) {
        const double angle = 2.0 * M_PI * k / curve_segments;
        const Eigen::Vector3d radial = radius * (std::cos(angle) * u + std::sin(angle) * v);
        model.points.push_back(a + radial);
        model.points.push_back(b + radial);
      }
      for (int k = 0; k < curve_segments; ++k) {
        const int j = (k + 1) % curve_segments;
        // (a_k, a_j, b_j, b_k): normal (a_j - a_k) x (b - a) points along the radial direction
        // since u x v = axis.
        model.polygons.push_back(
            {first + 2 * k, first + 2 * j, first + 2 * j + 1, first + 2 * k + 1});
      }
    }
  }

  if (!lines.done()) {  // circles: a flat polygon
    const long num_circles = read_count(lines, "circles");
    for (long i = 0; i < num_circles; ++i) {
      const CaoLine& line = lines.take("circle " + std::to_string(i) + " (radius centre p1 p2)");
      const double radius = read_number(lines, line, 0, "circle radius");
      const Eigen::Vector3d c =
          model.points[base + read_index(lines, line, 1, num_points, "point")];
      const Eigen::Vector3d p1 =
          model.points[base + read_index(lines, line, 2, num_points, "point")];
      const Eigen::Vector3d p2 =
          model.points[base + read_index(lines, line, 3, num_points, "point")];
      const Eigen::Vector3d normal = (p1 - c).cross(p2 - c);
      if (!(radius > 0.0) || !(normal.norm() > 0.0))
        throw lines.error(line, "a circle needs a radius > 0 and centre, p1, p2 not collinear");
      Eigen::Vector3d u, v;
      plane_basis(normal.normalized(), u, v);
      std::vector<int> polygon;
      for (int k = 0; k < curve_segments; ++k) {
        const double angle = 2.0 * M_PI * k / curve_segments;
        polygon.push_back(static_cast<int>(model.points.size()));
        model.points.push_back(c + radius * (std::cos(angle) * u + std::sin(angle) * v));
      }
      model.polygons.push_back(polygon);
    }
  }
  if (!lines.done())
    throw lines.error(lines.peek(), "unexpected content after the circles section");
  stack.pop_back();
}

}  // namespace

CaoModel read_cao(const std::string& path, int curve_segments) {
  if (curve_segments < 3 || curve_segments > 1024)
    throw std::invalid_argument("read_cao: curve_segments must be in [3, 1024], got " +
                                std::to_string(curve_segments));
  CaoModel model;
  std::vector<std::string> stack;
  read_file(path, curve_segments, 0, stack, model);
  if (model.polygons.empty())
    throw std::runtime_error("read_cao('" + path +
                             "'): the model has no faces (a surface needs faces from points or "
                             "lines, cylinders or circles; 3D lines alone cannot be tracked)");
  return model;
}

std::vector<std::array<int, 3>> triangulate_polygon(const std::vector<Eigen::Vector3d>& points,
                                                    const std::vector<int>& polygon) {
  // Hand-written ear clipping: assimp's aiProcess_Triangulate (5.2) was measured to return
  // overlapping triangles for a concave L-shaped hexagon (test_cao_reader), and CAD floors
  // and walls are often concave.
  std::vector<std::array<int, 3>> triangles;
  const int n = static_cast<int>(polygon.size());
  if (n < 3) return triangles;
  // Newell's normal: the polygon's orientation, robust to collinear and concave corners.
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d& a = points[polygon[i]];
    const Eigen::Vector3d& b = points[polygon[(i + 1) % n]];
    normal += Eigen::Vector3d((a.y() - b.y()) * (a.z() + b.z()), (a.z() - b.z()) * (a.x() + b.x()),
                              (a.x() - b.x()) * (a.y() + b.y()));
  }
  auto fan = [&](const std::vector<int>& loop) {
    for (std::size_t i = 1; i + 1 < loop.size(); ++i)
      triangles.push_back({loop[0], loop[i], loop[i + 1]});
  };
  if (!(normal.norm() > 0.0)) {  // degenerate (all points collinear): no area to cover
    fan(polygon);
    return triangles;
  }
  // 2D coordinates in the polygon's plane, counter-clockwise (u x v = normal).
  const Eigen::Vector3d w = normal.normalized();
  const Eigen::Vector3d u = w.unitOrthogonal(), v = w.cross(u);
  std::vector<Eigen::Vector2d> flat(n);
  double extent = 0.0;
  for (int i = 0; i < n; ++i) {
    flat[i] = Eigen::Vector2d(points[polygon[i]].dot(u), points[polygon[i]].dot(v));
    extent = std::max(extent, (flat[i] - flat[0]).norm());
  }
  const double eps = 1e-12 * extent * extent;
  auto cross = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
    return (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
  };
  std::vector<int> loop(n);  // positions into polygon / flat
  for (int i = 0; i < n; ++i) loop[i] = i;
  while (loop.size() > 3) {
    const int m = static_cast<int>(loop.size());
    bool clipped = false;
    for (int i = 0; i < m && !clipped; ++i) {
      const int a = loop[(i + m - 1) % m], b = loop[i], c = loop[(i + 1) % m];
      if (cross(flat[a], flat[b], flat[c]) <= eps) continue;  // reflex or collinear corner
      bool empty = true;  // no other corner inside or on the candidate ear
      for (int k = 0; k < m && empty; ++k) {
        const int q = loop[k];
        if (q == a || q == b || q == c) continue;
        if (flat[q] == flat[a] || flat[q] == flat[b] || flat[q] == flat[c]) continue;
        empty =
            !(cross(flat[a], flat[b], flat[q]) >= -eps &&
              cross(flat[b], flat[c], flat[q]) >= -eps && cross(flat[c], flat[a], flat[q]) >= -eps);
      }
      if (!empty) continue;
      triangles.push_back({polygon[a], polygon[b], polygon[c]});
      loop.erase(loop.begin() + i);
      clipped = true;
    }
    if (!clipped) break;  // self-intersecting outline: the rest as a fan (covers it roughly)
  }
  std::vector<int> rest;
  for (int i : loop) rest.push_back(polygon[i]);
  fan(rest);
  return triangles;
}

std::string cao_to_obj(const CaoModel& model) {
  std::ostringstream obj;
  obj.precision(17);
  for (const Eigen::Vector3d& p : model.points)
    obj << "v " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  for (const std::vector<int>& polygon : model.polygons)
    for (const auto& t : triangulate_polygon(model.points, polygon))  // OBJ indices are 1-based
      obj << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
  return obj.str();
}

}  // namespace kct
