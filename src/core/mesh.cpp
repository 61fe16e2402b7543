#include "klt_contour_tracker/core/mesh.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <array>
#include <cmath>
#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <unordered_map>
#include <utility>

#include "klt_contour_tracker/core/cao_reader.h"
#include "klt_contour_tracker/core/plausibility.h"

namespace kct {
namespace {

std::runtime_error mesh_error(const std::string& path, const std::string& reason) {
  return std::runtime_error("load_mesh('" + path + "'): " + reason);
}

std::string parent_folder(const std::string& path) {
  const auto slash = path.find_last_of("/\\");
  return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
}

bool file_exists(const std::string& path) { return std::ifstream(path).good(); }

bool has_cao_extension(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".cao";
}

/// Decodes an assimp embedded texture (compressed bytes or raw ARGB8888 texels) to BGR.
cv::Mat decode_embedded_texture(const aiTexture& texture) {
  if (texture.mHeight == 0) {
    const cv::Mat bytes(1, static_cast<int>(texture.mWidth), CV_8U,
                        const_cast<aiTexel*>(texture.pcData));
    return cv::imdecode(bytes, cv::IMREAD_COLOR);
  }
  cv::Mat bgr(static_cast<int>(texture.mHeight), static_cast<int>(texture.mWidth), CV_8UC3);
  for (int r = 0; r < bgr.rows; ++r)
    for (int c = 0; c < bgr.cols; ++c) {
      const aiTexel& t = texture.pcData[r * bgr.cols + c];
      bgr.at<cv::Vec3b>(r, c) = cv::Vec3b(t.b, t.g, t.r);
    }
  return bgr;
}

/// First diffuse texture of any material used by a mesh with faces; empty when none loads.
cv::Mat load_diffuse_texture(const aiScene& scene, const std::string& mesh_path) {
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh& mesh = *scene.mMeshes[m];
    if (mesh.mNumFaces == 0 || mesh.mMaterialIndex >= scene.mNumMaterials) continue;
    const aiMaterial& material = *scene.mMaterials[mesh.mMaterialIndex];
    if (material.GetTextureCount(aiTextureType_DIFFUSE) == 0) continue;
    aiString texture_path;
    if (material.GetTexture(aiTextureType_DIFFUSE, 0, &texture_path) != AI_SUCCESS) continue;
    if (const aiTexture* embedded = scene.GetEmbeddedTexture(texture_path.C_Str())) {
      cv::Mat texture = decode_embedded_texture(*embedded);
      if (!texture.empty()) return texture;
      continue;
    }
    std::string name = texture_path.C_Str();
    std::replace(name.begin(), name.end(), '\\', '/');
    const std::string folder = parent_folder(mesh_path);
    std::vector<std::string> candidates;
    if (!name.empty() && name[0] == '/') candidates.push_back(name);
    candidates.push_back(folder + "/" + name);
    const auto slash = name.find_last_of('/');
    if (slash != std::string::npos) candidates.push_back(folder + "/" + name.substr(slash + 1));
    for (const auto& candidate : candidates) {
      if (!file_exists(candidate)) continue;
      cv::Mat texture = cv::imread(candidate, cv::IMREAD_COLOR);
      if (!texture.empty()) return texture;
    }
  }
  return {};
}

/// Diffuse colour (BGR) of the first material used by a mesh with faces, if it has one.
bool diffuse_color(const aiScene& scene, cv::Vec3b& bgr) {
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh& mesh = *scene.mMeshes[m];
    if (mesh.mNumFaces == 0 || mesh.mMaterialIndex >= scene.mNumMaterials) continue;
    aiColor4D color;
    if (scene.mMaterials[mesh.mMaterialIndex]->Get(AI_MATKEY_COLOR_DIFFUSE, color) != AI_SUCCESS)
      return false;
    auto to_byte = [](float c) { return cv::saturate_cast<uchar>(std::lround(255.0f * c)); };
    bgr = cv::Vec3b(to_byte(color.b), to_byte(color.g), to_byte(color.r));
    return true;
  }
  return false;
}

/// Merges vertices closer than `tolerance` with a hash grid of cell size `tolerance`
/// (27-cell neighbourhood). Cells are counted from `origin` (the points' bounding-box corner),
/// so a cell index is at most (bounding-box size / tolerance) whatever the points' offset from
/// the object frame's origin: the float -> int64 conversion cannot overflow (the caller keeps
/// size / tolerance at 1e6). Returns the new index of every input vertex.
std::vector<int> merge_by_position(const std::vector<Eigen::Vector3d>& points,
                                   const Eigen::Vector3d& origin, double tolerance,
                                   std::vector<Eigen::Vector3d>& merged) {
  struct CellHash {
    std::size_t operator()(const std::array<int64_t, 3>& c) const {
      // Unsigned arithmetic: wraps (defined) where the signed products overflowed (UB).
      return static_cast<std::size_t>(static_cast<uint64_t>(c[0]) * 73856093ULL ^
                                      static_cast<uint64_t>(c[1]) * 19349663ULL ^
                                      static_cast<uint64_t>(c[2]) * 83492791ULL);
    }
  };
  std::unordered_map<std::array<int64_t, 3>, std::vector<int>, CellHash> grid;
  grid.reserve(points.size());
  std::vector<int> remap(points.size());
  merged.clear();
  const double tolerance2 = tolerance * tolerance;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d& p = points[i];
    const Eigen::Vector3d q = (p - origin) / tolerance;
    const std::array<int64_t, 3> cell{static_cast<int64_t>(std::floor(q.x())),
                                      static_cast<int64_t>(std::floor(q.y())),
                                      static_cast<int64_t>(std::floor(q.z()))};
    int found = -1;
    for (int dx = -1; dx <= 1 && found < 0; ++dx)
      for (int dy = -1; dy <= 1 && found < 0; ++dy)
        for (int dz = -1; dz <= 1 && found < 0; ++dz) {
          const auto it = grid.find({cell[0] + dx, cell[1] + dy, cell[2] + dz});
          if (it == grid.end()) continue;
          for (int candidate : it->second)
            if ((merged[candidate] - p).squaredNorm() <= tolerance2) {
              found = candidate;
              break;
            }
        }
    if (found < 0) {
      found = static_cast<int>(merged.size());
      merged.push_back(p);
      grid[cell].push_back(found);
    }
    remap[i] = found;
  }
  return remap;
}

/// Lower-cases ASCII letters.
std::string lower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

/// Bytes one PLY scalar type takes in a binary file; 0 for an unknown name.
std::uint64_t ply_type_bytes(const std::string& type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "float" || type == "int32" || type == "uint32" ||
      type == "float32")
    return 4;
  if (type == "double" || type == "float64") return 8;
  return 0;
}

/// Checks the token structure of an ASCII STL (solid ... (facet normal x y z outer loop
/// (vertex x y z){3} endloop endfacet)* endsolid, repeatable), since assimp 5's ASCII STL reader
/// leaks the meshes it has built when it throws on a malformed file (LeakSanitizer, issue 8).
/// Hand-written because assimp offers no validation without importing.
void check_ascii_stl(const std::string& path, std::istream& in) {
  std::string token;
  std::size_t line_tokens = 0;
  auto next = [&](std::string& out) -> bool {
    if (!(in >> out)) return false;
    ++line_tokens;
    return true;
  };
  auto fail = [&](const std::string& what) {
    throw mesh_error(path, "malformed ASCII STL: " + what + " (token " +
                               std::to_string(line_tokens) + ")");
  };
  auto expect = [&](const char* keyword) {
    if (!next(token) || lower(token) != keyword)
      fail(std::string("expected '") + keyword + "', got '" + truncate_for_message(token, 32) + "'");
  };
  auto number = [&]() {
    if (!next(token)) fail("missing number");
    char* end = nullptr;
    std::strtod(token.c_str(), &end);
    if (end == token.c_str() || *end != '\0')
      fail("'" + truncate_for_message(token, 32) + "' is not a number");
  };
  bool any_facet = false;
  while (next(token)) {
    if (lower(token) != "solid") fail("expected 'solid', got '" + truncate_for_message(token, 32) + "'");
    std::string name_line;
    std::getline(in, name_line);  // the solid's name: anything up to the end of the line
    while (true) {
      if (!next(token)) fail("missing 'endsolid'");
      const std::string keyword = lower(token);
      if (keyword == "endsolid") {
        std::getline(in, name_line);
        break;
      }
      if (keyword != "facet") fail("expected 'facet' or 'endsolid', got '" + truncate_for_message(token, 32) + "'");
      expect("normal");
      number(), number(), number();
      expect("outer");
      expect("loop");
      for (int k = 0; k < 3; ++k) {
        expect("vertex");
        number(), number(), number();
      }
      expect("endloop");
      expect("endfacet");
      any_facet = true;
    }
  }
  if (!any_facet) fail("no facet");
}

/// Checks an OFF file's structure (header, counts, vertex lines of 3 numbers, face lines
/// "n i_1 .. i_n" with n >= 3 and indices below the vertex count; '#' comments): on malformed
/// faces assimp 5's triangulation hits an ai_assert that aborts the process (libFuzzer found it;
/// Debian builds assimp with assertions), which for the nodelet would take down the manager.
/// Hand-written because assimp offers no validation without importing.
void check_off(const std::string& path, std::istream& in) {
  auto fail = [&](const std::string& what) {
    throw mesh_error(path, "malformed OFF: " + what);
  };
  std::vector<std::vector<std::string>> lines;
  std::string line;
  while (std::getline(in, line)) {
    if (line.find('\0') != std::string::npos) fail("NUL byte in line " + std::to_string(lines.size() + 1));
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream words(line);
    std::vector<std::string> tokens;
    for (std::string t; words >> t;) tokens.push_back(t);
    if (!tokens.empty()) lines.push_back(std::move(tokens));
  }
  auto integer = [&](const std::string& token, std::uint64_t& value) {
    char* end = nullptr;
    const unsigned long long v = std::strtoull(token.c_str(), &end, 10);
    if (end == token.c_str() || *end != '\0' || token[0] == '-') return false;
    value = v;
    return true;
  };
  auto number = [&](const std::string& token) {
    char* end = nullptr;
    std::strtod(token.c_str(), &end);
    return end != token.c_str() && *end == '\0';
  };
  if (lines.empty()) fail("empty file");
  std::size_t row = 0;
  std::vector<std::string> counts = lines[row];
  if (counts[0].size() >= 3 && counts[0].compare(counts[0].size() - 3, 3, "OFF") == 0) {
    counts.erase(counts.begin());
    if (counts.empty()) {
      if (++row >= lines.size()) fail("no counts line");
      counts = lines[row];
    }
  }
  std::uint64_t vertices = 0, faces = 0;
  if (counts.size() < 2 || !integer(counts[0], vertices) || !integer(counts[1], faces))
    fail("the counts line must start with the vertex and face counts");
  if (lines.size() - row - 1 < vertices + faces)
    fail("declares " + std::to_string(vertices) + " vertices and " + std::to_string(faces) +
         " faces but has " + std::to_string(lines.size() - row - 1) + " lines");
  for (std::uint64_t v = 0; v < vertices; ++v) {
    const auto& tokens = lines[++row];
    if (tokens.size() < 3 || !number(tokens[0]) || !number(tokens[1]) || !number(tokens[2]))
      fail("vertex " + std::to_string(v) + " is not 3 numbers");
  }
  for (std::uint64_t f = 0; f < faces; ++f) {
    const auto& tokens = lines[++row];
    std::uint64_t n = 0;
    if (!integer(tokens[0], n) || n < 3 || tokens.size() < n + 1)
      fail("face " + std::to_string(f) + " is not 'n i_1 .. i_n' with n >= 3");
    for (std::uint64_t k = 1; k <= n; ++k) {
      std::uint64_t index = 0;
      if (!integer(tokens[k], index) || index >= vertices)
        fail("face " + std::to_string(f) + " has an invalid vertex index '" +
             truncate_for_message(tokens[k], 32) + "'");
    }
  }
}

/// Checks what a file's header promises against the file's size before assimp reads it:
/// assimp allocates what a PLY header declares (100M vertices: 1.2 GB for a 200-byte file) and
/// what a binary STL's facet count says. Hand-written because assimp has no such pre-check.
/// Throws std::runtime_error (via mesh_error) when the file cannot hold what its header declares.
void check_header_against_size(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  in.seekg(0, std::ios::end);
  const std::uint64_t file_size = static_cast<std::uint64_t>(std::max<std::streamoff>(0, in.tellg()));
  in.seekg(0);
  char magic[5] = {0};
  in.read(magic, 5);
  in.clear();
  in.seekg(0);
  const std::string head(magic, static_cast<std::size_t>(in.gcount() > 0 ? 5 : 0));
  std::string extension;
  const auto dot = path.find_last_of('.');
  if (dot != std::string::npos) extension = lower(path.substr(dot + 1));

  if (head.compare(0, 3, "ply") == 0) {
    // Header: text lines up to "end_header" (at most 64 KB).
    bool binary = false;
    std::uint64_t header_bytes = 0, needed = 0;
    std::uint64_t count = 0, per_element = 0;
    std::string line;
    bool ended = false;
    auto close_element = [&]() {
      const long double total = static_cast<long double>(count) * per_element;
      needed = total > 1e18L ? std::numeric_limits<std::uint64_t>::max()
                             : needed + static_cast<std::uint64_t>(total);
      count = per_element = 0;
    };
    while (header_bytes < 65536 && std::getline(in, line)) {
      header_bytes += line.size() + 1;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      std::istringstream words(line);
      std::string keyword;
      words >> keyword;
      if (keyword == "format") {
        std::string format;
        words >> format;
        binary = format != "ascii";
      } else if (keyword == "element") {
        close_element();
        std::string name, count_text;
        words >> name >> count_text;
        try {
          std::size_t used = 0;
          count = std::stoull(count_text, &used);
          if (used != count_text.size()) throw std::invalid_argument(count_text);
        } catch (const std::exception&) {
          throw mesh_error(path, "PLY header: element '" + truncate_for_message(name) +
                                     "' has an invalid count '" +
                                     truncate_for_message(count_text) + "'");
        }
      } else if (keyword == "property") {
        std::string type, count_type;
        words >> type;
        if (type == "list") {
          words >> count_type;  // a list takes at least its count
          per_element += binary ? std::max<std::uint64_t>(1, ply_type_bytes(count_type)) : 2;
        } else {
          per_element += binary ? std::max<std::uint64_t>(1, ply_type_bytes(type)) : 2;
        }
      } else if (keyword == "end_header") {
        close_element();
        ended = true;
        break;
      }
    }
    if (!ended) throw mesh_error(path, "PLY header: no end_header in the first 64 KB");
    if (needed > file_size - std::min(file_size, header_bytes))
      throw mesh_error(path, "PLY header declares elements needing at least " +
                                 std::to_string(needed) + " bytes, but the file has " +
                                 std::to_string(file_size) + " bytes (truncated or corrupt)");
    return;
  }
  if (extension == "off") {
    check_off(path, in);
    return;
  }
  if (extension == "stl" && head == "solid") {
    // A binary STL may start with "solid" too: assimp takes the size match as binary.
    if (file_size >= 84) {
      unsigned char count_bytes[4];
      in.seekg(80);
      in.read(reinterpret_cast<char*>(count_bytes), 4);
      in.clear();
      const std::uint64_t facets = static_cast<std::uint64_t>(count_bytes[0]) |
                                   static_cast<std::uint64_t>(count_bytes[1]) << 8 |
                                   static_cast<std::uint64_t>(count_bytes[2]) << 16 |
                                   static_cast<std::uint64_t>(count_bytes[3]) << 24;
      if (84 + 50 * facets == file_size) return;
    }
    in.seekg(0);
    check_ascii_stl(path, in);
    return;
  }
  if (extension == "stl" && head != "solid") {
    // Binary STL: 80-byte header, uint32 facet count, 50 bytes per facet.
    if (file_size < 84)
      throw mesh_error(path, "binary STL of " + std::to_string(file_size) +
                                 " bytes is shorter than its 84-byte header");
    unsigned char count_bytes[4];
    in.seekg(80);
    in.read(reinterpret_cast<char*>(count_bytes), 4);
    const std::uint64_t facets = static_cast<std::uint64_t>(count_bytes[0]) |
                                 static_cast<std::uint64_t>(count_bytes[1]) << 8 |
                                 static_cast<std::uint64_t>(count_bytes[2]) << 16 |
                                 static_cast<std::uint64_t>(count_bytes[3]) << 24;
    if (facets == 0 || 84 + 50 * facets > file_size)
      throw mesh_error(path, "binary STL declares " + std::to_string(facets) +
                                 " facets (" + std::to_string(84 + 50 * facets) +
                                 " bytes) but the file has " + std::to_string(file_size) +
                                 " bytes (truncated or corrupt)");
  }
}

double max_pairwise_distance(const std::vector<Eigen::Vector3d>& points) {
  double best2 = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i)
    for (std::size_t j = i + 1; j < points.size(); ++j)
      best2 = std::max(best2, (points[i] - points[j]).squaredNorm());
  return std::sqrt(best2);
}

}  // namespace

// Diameter: exact brute force over a pruned candidate set. A lower bound L comes from the
// extreme vertices along many directions; a vertex p can only belong to a pair longer than L
// if |p - c| + R > L (c, R: bounding-box centre and the radius around it), so the others are
// dropped. Boxy and elongated models leave a handful of candidates (exact result). Near-round
// models may keep most vertices; above 4000 candidates only the directional extremes are
// compared, which underestimates by at most ~0.2 % with 1024 directions (documented bound:
// 1 - cos of half the direction spacing).
double Mesh::diameter() const {
  if (vertices.size() < 2) return 0.0;
  if (vertices.size() <= 2000) return max_pairwise_distance(vertices);
  const Eigen::Vector3d center = bounding_box_center();
  const double radius = radius_about(center);

  constexpr int kDirections = 1024;
  std::vector<int> extreme_ids;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int k = 0; k < kDirections; ++k) {  // Fibonacci half-sphere: min and max per direction
    const double z = 1.0 - (k + 0.5) / kDirections;
    const double r = std::sqrt(1.0 - z * z);
    const Eigen::Vector3d d(r * std::cos(golden * k), r * std::sin(golden * k), z);
    int lo = 0, hi = 0;
    double lo_value = std::numeric_limits<double>::max(), hi_value = -lo_value;
    for (std::size_t i = 0; i < vertices.size(); ++i) {
      const double s = d.dot(vertices[i]);
      if (s < lo_value) lo_value = s, lo = static_cast<int>(i);
      if (s > hi_value) hi_value = s, hi = static_cast<int>(i);
    }
    extreme_ids.push_back(lo);
    extreme_ids.push_back(hi);
  }
  std::sort(extreme_ids.begin(), extreme_ids.end());
  extreme_ids.erase(std::unique(extreme_ids.begin(), extreme_ids.end()), extreme_ids.end());
  std::vector<Eigen::Vector3d> extremes;
  for (int id : extreme_ids) extremes.push_back(vertices[id]);
  const double lower_bound = max_pairwise_distance(extremes);

  std::vector<Eigen::Vector3d> candidates;
  for (const auto& v : vertices)
    if ((v - center).norm() + radius > lower_bound) candidates.push_back(v);
  if (candidates.size() > 4000) return lower_bound;
  return std::max(lower_bound, max_pairwise_distance(candidates));
}

Eigen::AlignedBox3d Mesh::bounding_box() const {
  Eigen::AlignedBox3d box;  // empty
  for (const auto& v : vertices) box.extend(v);
  return box;
}

Eigen::Vector3d Mesh::bounding_box_center() const {
  if (vertices.empty()) return Eigen::Vector3d::Zero();
  return bounding_box().center();
}

double Mesh::radius_about(const Eigen::Vector3d& center_object) const {
  double radius = 0.0;
  for (const auto& v : vertices) radius = std::max(radius, (v - center_object).norm());
  return radius;
}

Eigen::Vector3d Mesh::face_normal(int face) const {
  const Eigen::Vector3i& f = faces.at(face);
  const Eigen::Vector3d n =
      (vertices[f[1]] - vertices[f[0]]).cross(vertices[f[2]] - vertices[f[0]]);
  const double length = n.norm();
  return length > 0.0 ? Eigen::Vector3d(n / length) : Eigen::Vector3d::Zero();
}

std::vector<MeshEdge> Mesh::shared_edges() const {
  // (edge key, face) pairs sorted by key: a deterministic order without a hash map.
  std::vector<std::pair<uint64_t, int>> entries;
  entries.reserve(faces.size() * 3);
  for (int f = 0; f < static_cast<int>(faces.size()); ++f)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = static_cast<uint32_t>(faces[f][k]);
      const uint32_t b = static_cast<uint32_t>(faces[f][(k + 1) % 3]);
      if (a == b) continue;
      entries.emplace_back((static_cast<uint64_t>(std::min(a, b)) << 32) | std::max(a, b), f);
    }
  std::sort(entries.begin(), entries.end());
  std::vector<MeshEdge> edges;
  for (std::size_t i = 0; i < entries.size();) {
    std::size_t j = i;
    while (j < entries.size() && entries[j].first == entries[i].first) ++j;
    if (j - i == 2 && entries[i].second != entries[i + 1].second)
      edges.push_back({static_cast<int>(entries[i].first >> 32),
                       static_cast<int>(entries[i].first & 0xffffffffu), entries[i].second,
                       entries[i + 1].second});
    i = j;
  }
  return edges;
}

Mesh load_mesh(const std::string& path, double scale) {
  if (!(std::isfinite(scale) && scale > 0.0))
    throw mesh_error(path, "scale must be finite and > 0 (got " + std::to_string(scale) + ")");
  if (!file_exists(path)) throw mesh_error(path, "file not found or not readable");
  check_header_against_size(path);

  Assimp::Importer importer;
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                         aiProcess_PreTransformVertices | aiProcess_SortByPType;
  // ViSP's .cao (not an assimp format): read and triangulated by cao_reader, handed to assimp
  // as OBJ text so that the rest (merging, scale, checks) is shared with every other format.
  const bool cao = has_cao_extension(path);
  std::string cao_obj;
  if (cao) cao_obj = cao_to_obj(read_cao(path));
  const aiScene* scene = cao ? importer.ReadFileFromMemory(cao_obj.data(), cao_obj.size(), flags,
                                                           "obj")
                             : importer.ReadFile(path, flags);
  if (scene == nullptr || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0)
    throw mesh_error(path, std::string("assimp failed: ") + importer.GetErrorString());

  // Raw triangle soup (3 corners per face) in the file's units, then merge by position.
  std::vector<Eigen::Vector3d> corners;
  std::vector<Eigen::Vector2f> uvs;
  bool any_uv = false;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh& mesh = *scene->mMeshes[m];
    const bool has_uv = mesh.HasTextureCoords(0);
    any_uv = any_uv || has_uv;
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices != 3) continue;
      for (int k = 0; k < 3; ++k) {
        const unsigned idx = face.mIndices[k];
        const aiVector3D& p = mesh.mVertices[idx];
        corners.emplace_back(p.x * scale, p.y * scale, p.z * scale);
        uvs.emplace_back(has_uv ? Eigen::Vector2f(mesh.mTextureCoords[0][idx].x,
                                                  mesh.mTextureCoords[0][idx].y)
                                : Eigen::Vector2f::Zero());
      }
    }
  }
  if (corners.empty()) throw mesh_error(path, "the file contains no triangles");
  for (const auto& c : corners)
    if (!c.allFinite()) throw mesh_error(path, "a vertex coordinate is not finite");

  Eigen::AlignedBox3d box;
  for (const auto& c : corners) box.extend(c);
  // The bounding-box diagonal (between 1 and sqrt(3) object diameters) bounds the model's size
  // before anything depends on it: a scale of 1e300 or a mesh in the wrong unit is named here.
  const double size = box.diagonal().norm();
  if (!(size > 0.0)) throw mesh_error(path, "all vertices coincide");
  if (!(size >= PlausibilityLimits::kMinDiameterM && size <= PlausibilityLimits::kMaxDiameterM))
    throw mesh_error(path, "the model is " + format_number(size) +
                               " m across (bounding-box diagonal) after scaling by " +
                               format_number(scale) + ": allowed [" +
                               format_number(PlausibilityLimits::kMinDiameterM) + ", " +
                               format_number(PlausibilityLimits::kMaxDiameterM) +
                               "] m; is the scale right? (--model-scale / ~mesh_scale, e.g. "
                               "0.001 for a model in millimetres)");

  Mesh result;
  const std::vector<int> remap = merge_by_position(corners, box.min(), 1e-6 * size, result.vertices);
  // Zero-area faces (repeated or collinear corners) have no normal and no contour: dropped.
  const double min_double_area = 1e-12 * size * size;
  for (std::size_t f = 0; f < corners.size() / 3; ++f) {
    const Eigen::Vector3i face(remap[3 * f], remap[3 * f + 1], remap[3 * f + 2]);
    if (face[0] == face[1] || face[1] == face[2] || face[0] == face[2]) continue;  // degenerate
    const Eigen::Vector3d& a = result.vertices[face[0]];
    if (!((result.vertices[face[1]] - a).cross(result.vertices[face[2]] - a).norm() >
          min_double_area))
      continue;  // collinear corners
    result.faces.push_back(face);
    if (any_uv)
      for (int k = 0; k < 3; ++k) result.corner_uvs.push_back(uvs[3 * f + k]);
  }
  if (result.faces.empty())
    throw mesh_error(path, "every triangle is degenerate (zero area: repeated or collinear corners)");

  cv::Vec3b color;
  if (!cao && diffuse_color(*scene, color) && color != cv::Vec3b(0, 0, 0))
    result.base_color = color;
  if (any_uv) result.texture = load_diffuse_texture(*scene, path);
  if (result.texture.empty()) result.corner_uvs.clear();
  return result;
}

namespace {

/// Texture of a part for an atlas: its own, or a small patch of its base colour.
cv::Mat part_texture(const Mesh& mesh) {
  if (mesh.has_texture()) return mesh.texture;
  return cv::Mat(8, 8, CV_8UC3, cv::Scalar(mesh.base_color[0], mesh.base_color[1],
                                           mesh.base_color[2]));
}

std::vector<Eigen::Vector2f> part_uvs(const Mesh& mesh) {
  if (mesh.has_texture()) return mesh.corner_uvs;
  return std::vector<Eigen::Vector2f>(mesh.faces.size() * 3, Eigen::Vector2f(0.5f, 0.5f));
}

}  // namespace

// Two textured parts are combined in a side-by-side atlas (each part resized to a common
// height); an untextured part gets a patch of its base colour. UVs are remapped into the
// atlas, so parts relying on repeat-wrapped UVs (outside [0, 1]) lose the repetition.
void append_mesh(Mesh& mesh, const Mesh& other, const Eigen::Isometry3d& transform) {
  if (other.faces.empty()) return;
  if (mesh.faces.empty()) {
    const Eigen::Isometry3d t = transform;
    mesh = other;
    for (auto& v : mesh.vertices) v = t * v;
    return;
  }
  const bool textured = mesh.has_texture() || other.has_texture();
  if (textured) {
    const cv::Mat a = part_texture(mesh), b = part_texture(other);
    const int height = std::max(a.rows, b.rows);
    cv::Mat a_resized = a, b_resized = b;
    if (a.rows != height)
      cv::resize(a, a_resized, cv::Size(std::max(1, a.cols * height / a.rows), height));
    if (b.rows != height)
      cv::resize(b, b_resized, cv::Size(std::max(1, b.cols * height / b.rows), height));
    const float width = static_cast<float>(a_resized.cols + b_resized.cols);
    std::vector<Eigen::Vector2f> uvs;
    for (const auto& uv : part_uvs(mesh))
      uvs.emplace_back(uv.x() * a_resized.cols / width, uv.y());
    for (const auto& uv : part_uvs(other))
      uvs.emplace_back((a_resized.cols + uv.x() * b_resized.cols) / width, uv.y());
    cv::hconcat(a_resized, b_resized, mesh.texture);
    mesh.corner_uvs = std::move(uvs);
  }
  const int offset = static_cast<int>(mesh.vertices.size());
  for (const auto& v : other.vertices) mesh.vertices.push_back(transform * v);
  for (const auto& f : other.faces) mesh.faces.push_back(f + Eigen::Vector3i::Constant(offset));
}

}  // namespace kct
