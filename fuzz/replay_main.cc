// A main for fuzz targets built without libFuzzer (GCC): runs
// LLVMFuzzerTestOneInput once on every file of the directories and files
// named on the command line, so the committed corpora run as CTest tests.
// Exit 0 when every input ran; 2 when a path is missing, unreadable, or a
// directory holds no inputs (a corpus that vanished must not pass silently).
// A failing input stops the run the way it would stop libFuzzer: by a trap
// or abort in the target, which CTest reports.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

namespace fs = std::filesystem;

bool RunOne(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "replay: cannot read '%s'\n", file.c_str());
    return false;
  }
  // The input in an allocation of its exact size, so ASan sees reads past its end.
  std::vector<std::uint8_t> input((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  LLVMFuzzerTestOneInput(input.data(), input.size());
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s CORPUS_DIR_OR_FILE...\n", argv[0]);
    return 2;
  }
  std::size_t ran = 0;
  for (int i = 1; i < argc; ++i) {
    const fs::path path = argv[i];
    std::error_code ec;
    if (fs::is_directory(path, ec)) {
      std::vector<fs::path> files;
      for (const auto& entry : fs::recursive_directory_iterator(path, ec)) {
        if (entry.is_regular_file()) files.push_back(entry.path());
      }
      if (ec || files.empty()) {
        std::fprintf(stderr, "replay: directory '%s' holds no inputs\n", path.c_str());
        return 2;
      }
      std::sort(files.begin(), files.end());  // a stable order, for reading logs
      for (const fs::path& file : files) {
        if (!RunOne(file)) return 2;
        ++ran;
      }
    } else if (fs::is_regular_file(path, ec)) {
      if (!RunOne(path)) return 2;
      ++ran;
    } else {
      std::fprintf(stderr, "replay: '%s' does not exist\n", path.c_str());
      return 2;
    }
  }
  std::printf("replay: %zu inputs ran without a failure\n", ran);
  return 0;
}
