// libFuzzer target: kct::load_mesh() on arbitrary file contents. The first byte picks the file
// extension (assimp chooses its importer by it and by the contents); the rest is the file.
// Any exception other than the documented std::runtime_error, any sanitizer report, leak or
// allocation above -rss_limit_mb is a failure.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>

#include "klt_contour_tracker/core/mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const char* const kExtensions[] = {"obj", "stl", "ply", "off", "dae", "gltf", "cao"};
  if (size < 1) return 0;
  const std::string extension = kExtensions[data[0] % (sizeof(kExtensions) / sizeof(*kExtensions))];
  const std::string path = "/tmp/kct_fuzz_mesh_" + std::to_string(getpid()) + "." + extension;
  {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
  }
  try {
    const kct::Mesh mesh = kct::load_mesh(path, 1.0);
    if (mesh.faces.empty()) __builtin_trap();  // load_mesh promises faces or an exception
    for (const auto& f : mesh.faces)
      for (int k = 0; k < 3; ++k)
        if (f[k] < 0 || f[k] >= static_cast<int>(mesh.vertices.size())) __builtin_trap();
  } catch (const std::runtime_error&) {
  }
  std::remove(path.c_str());
  return 0;
}
