#include "klt_contour_tracker/core/visibility_table.h"

#include <opencv2/core.hpp>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "klt_contour_tracker/core/renderer.h"

namespace kct {
namespace {

constexpr char kMagic[8] = {'K', 'C', 'T', 'V', 'I', 'S', '\0', '\1'};
// Bump when the file layout or the meaning of the stored bits changes.
constexpr std::uint64_t kFormatVersion = 1;

/// FNV-1a 64-bit over raw bytes. Hand-written because neither OpenCV nor the STL offers a
/// stable (cross-run, cross-platform) 64-bit hash; std::hash is implementation-defined.
class Fnv1a {
 public:
  void add(const void* data, std::size_t size) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) {
      state_ ^= p[i];
      state_ *= 0x100000001b3ull;
    }
  }
  template <typename T>
  void add_value(const T& value) {
    add(&value, sizeof(T));
  }
  std::uint64_t value() const { return state_; }

 private:
  std::uint64_t state_ = 0xcbf29ce484222325ull;
};

std::uint64_t table_hash(const Mesh& mesh, int subdivisions, int resolution_px) {
  Fnv1a h;
  h.add_value(kFormatVersion);
  h.add_value(static_cast<std::int64_t>(subdivisions));
  h.add_value(static_cast<std::int64_t>(resolution_px));
  h.add_value(static_cast<std::uint64_t>(mesh.vertices.size()));
  h.add_value(static_cast<std::uint64_t>(mesh.faces.size()));
  for (const Eigen::Vector3d& v : mesh.vertices) h.add(v.data(), 3 * sizeof(double));
  for (const Eigen::Vector3i& f : mesh.faces) {
    const std::int32_t ids[3] = {f[0], f[1], f[2]};
    h.add(ids, sizeof(ids));
  }
  return h.value();
}

std::uint64_t bits_checksum(const VisibilityTable::Bits& bits) {
  Fnv1a h;
  h.add(bits.data(), bits.size() * sizeof(std::uint64_t));
  return h.value();
}

struct CacheHeader {
  char magic[8];
  std::uint64_t hash;
  std::int32_t subdivisions, resolution_px, face_count, viewpoint_count;
  std::uint64_t words;
};

}  // namespace

VisibilityTable::VisibilityTable(int subdivisions, int resolution_px, int face_count,
                                 const Eigen::Vector3d& center_object)
    : icosphere_(subdivisions),
      resolution_px_(resolution_px),
      face_count_(face_count),
      words_((static_cast<std::size_t>(face_count) + 63) / 64),
      center_object_(center_object),
      bits_(icosphere_.vertices().size() * words_, 0) {}

std::string VisibilityTable::cache_file_path(const Mesh& mesh, int subdivisions,
                                             int resolution_px, const std::string& cache_dir) {
  char name[64];
  std::snprintf(name, sizeof(name), "visibility_%016llx.bin",
                static_cast<unsigned long long>(table_hash(mesh, subdivisions, resolution_px)));
  return (std::filesystem::path(cache_dir) / name).string();
}

std::shared_ptr<const VisibilityTable> VisibilityTable::build(const Mesh& mesh, int subdivisions,
                                                              int resolution_px,
                                                              const std::string& cache_dir) {
  if (mesh.vertices.empty() || mesh.faces.empty())
    throw std::invalid_argument("VisibilityTable::build: the mesh has no faces");
  if (subdivisions < 0 || subdivisions > 7)
    throw std::invalid_argument("VisibilityTable::build: subdivisions must be in [0, 7], got " +
                                std::to_string(subdivisions));
  if (resolution_px < 16 || resolution_px > 4096)
    throw std::invalid_argument(
        "VisibilityTable::build: resolution_px must be in [16, 4096], got " +
        std::to_string(resolution_px));

  auto table = std::make_shared<VisibilityTable>(subdivisions, resolution_px,
                                                 static_cast<int>(mesh.faces.size()),
                                                 mesh.bounding_box_center());
  const std::uint64_t hash = table_hash(mesh, subdivisions, resolution_px);
  std::string path;
  if (!cache_dir.empty()) {
    path = cache_file_path(mesh, subdivisions, resolution_px, cache_dir);
    if (table->read_cache(path, hash)) {
      table->loaded_from_cache_ = true;
      return table;
    }
  }

  // Geometry only: the renderer needs no texture for a face-index render.
  auto geometry = std::make_shared<Mesh>();
  geometry->vertices = mesh.vertices;
  geometry->faces = mesh.faces;
  const Renderer renderer(geometry);

  const int face_count = table->face_count_;
  const std::size_t words = table->words_;
  const std::vector<Eigen::Vector3d>& directions = table->icosphere_.vertices();
  Bits& bits = table->bits_;
  cv::parallel_for_(cv::Range(0, static_cast<int>(directions.size())), [&](const cv::Range& r) {
    std::vector<std::uint8_t> seen(face_count);
    for (int u = r.start; u < r.end; ++u) {
      const cv::Mat index = renderer.render_face_index_orthographic(-directions[u], resolution_px);
      std::fill(seen.begin(), seen.end(), 0);
      for (int y = 0; y < index.rows; ++y) {
        const std::int32_t* row = index.ptr<std::int32_t>(y);
        for (int x = 0; x < index.cols; ++x)
          if (row[x] >= 0 && row[x] < face_count) seen[row[x]] = 1;
      }
      std::uint64_t* out = bits.data() + static_cast<std::size_t>(u) * words;
      for (int f = 0; f < face_count; ++f)
        if (!seen[f]) out[f >> 6] |= std::uint64_t{1} << (f & 63);
    }
  });

  if (!path.empty()) table->write_cache(path, hash);
  return table;
}

bool VisibilityTable::read_cache(const std::string& path, std::uint64_t hash) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  CacheHeader header{};
  if (!in.read(reinterpret_cast<char*>(&header), sizeof(header))) return false;
  if (std::memcmp(header.magic, kMagic, sizeof(kMagic)) != 0 || header.hash != hash ||
      header.subdivisions != icosphere_.subdivisions() || header.resolution_px != resolution_px_ ||
      header.face_count != face_count_ || header.viewpoint_count != viewpoint_count() ||
      header.words != words_)
    return false;
  Bits bits(bits_.size());
  std::uint64_t checksum = 0;
  if (!in.read(reinterpret_cast<char*>(bits.data()), bits.size() * sizeof(std::uint64_t)) ||
      !in.read(reinterpret_cast<char*>(&checksum), sizeof(checksum)))
    return false;
  if (in.peek() != std::char_traits<char>::eof() || checksum != bits_checksum(bits)) return false;
  bits_ = std::move(bits);
  return true;
}

void VisibilityTable::write_cache(const std::string& path, std::uint64_t hash) const {
  std::error_code error;
  const std::filesystem::path target(path);
  std::filesystem::create_directories(target.parent_path(), error);
  // Write to a temporary name, then rename: a reader never sees a half-written file.
  const std::filesystem::path temporary =
      target.string() + "." +
      std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()) + ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) return;
    CacheHeader header{};
    std::memcpy(header.magic, kMagic, sizeof(kMagic));
    header.hash = hash;
    header.subdivisions = icosphere_.subdivisions();
    header.resolution_px = resolution_px_;
    header.face_count = face_count_;
    header.viewpoint_count = viewpoint_count();
    header.words = words_;
    const std::uint64_t checksum = bits_checksum(bits_);
    out.write(reinterpret_cast<const char*>(&header), sizeof(header));
    out.write(reinterpret_cast<const char*>(bits_.data()), bits_.size() * sizeof(std::uint64_t));
    out.write(reinterpret_cast<const char*>(&checksum), sizeof(checksum));
    if (!out) {
      out.close();
      std::filesystem::remove(temporary, error);
      return;
    }
  }
  std::filesystem::rename(temporary, target, error);
  if (error) std::filesystem::remove(temporary, error);
}

void VisibilityTable::invisible_bits(int icosphere_face, Bits& invisible) const {
  const Eigen::Vector3i& f = icosphere_.faces().at(icosphere_face);
  const std::uint64_t* a = invisible_from_viewpoint(f[0]);
  const std::uint64_t* b = invisible_from_viewpoint(f[1]);
  const std::uint64_t* c = invisible_from_viewpoint(f[2]);
  invisible.resize(words_);
  for (std::size_t w = 0; w < words_; ++w) invisible[w] = a[w] & b[w] & c[w];
}

void VisibilityTable::invisible_faces(const Eigen::Vector3d& direction_to_camera_object,
                                      std::vector<std::uint8_t>& invisible) const {
  const Eigen::Vector3i f = icosphere_.face_vertices_containing(direction_to_camera_object);
  const std::uint64_t* a = invisible_from_viewpoint(f[0]);
  const std::uint64_t* b = invisible_from_viewpoint(f[1]);
  const std::uint64_t* c = invisible_from_viewpoint(f[2]);
  invisible.resize(face_count_);
  for (int face = 0; face < face_count_; ++face) {
    const int w = face >> 6;
    invisible[face] = static_cast<std::uint8_t>(((a[w] & b[w] & c[w]) >> (face & 63)) & 1u);
  }
}

}  // namespace kct
