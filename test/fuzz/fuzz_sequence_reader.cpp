// libFuzzer target: the sequence folder reader (kct::read_sequence, read_image_size) on
// arbitrary K.txt, pose.txt and frame contents. The input is split at the first two 0xff bytes:
// K.txt | pose.txt | 000000.png. Only std::runtime_error / std::invalid_argument may leave.
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "klt_contour_tracker/core/sequence_io.h"

namespace {

void write(const std::filesystem::path& path, const uint8_t* data, size_t size) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  namespace fs = std::filesystem;
  static const fs::path dir = fs::temp_directory_path() / ("kct_fuzz_seq_" + std::to_string(getpid()));
  fs::create_directories(dir);
  size_t parts[3] = {0, 0, 0}, begin[3] = {0, 0, 0};
  int part = 0;
  for (size_t i = 0; i < size; ++i) {
    if (data[i] == 0xff && part < 2) {
      begin[++part] = i + 1;
      continue;
    }
    ++parts[part];
  }
  write(dir / "K.txt", data + begin[0], parts[0]);
  write(dir / "pose.txt", data + begin[1], parts[1]);
  write(dir / "000000.png", data + begin[2], parts[2]);
  try {
    const kct::SequenceFolder folder = kct::read_sequence(dir.string());
    kct::read_image_size(folder.image_paths.at(0));
  } catch (const std::runtime_error&) {
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
