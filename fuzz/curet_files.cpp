// Fuzz target: the CUReT files (brdf/curet.hpp load_curet) that `roughscope curet --data DIR`
// reads. The library reads a directory, so the input is split at the byte 0x1E (ASCII record
// separator) into up to four files written to a per-process temporary directory:
//   part 1 → table.txt, part 2 → abrdf.dat, part 3 → aover.dat, part 4 → rover.dat
// A missing or empty part means the file is absent. The mean channel is loaded and every sample
// is turned into a BrdfTable (the paper's frame, §2).
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <unistd.h>

#include "fuzz_target.hpp"
#include "roughscope/brdf/curet.hpp"

namespace {

namespace fs = std::filesystem;

constexpr char kSeparator = '\x1e';
constexpr const char* kFileNames[] = {"table.txt", "abrdf.dat", "aover.dat", "rover.dat"};

// A fresh directory under the system temporary directory, removed at exit.
class TemporaryDirectory {
  public:
    TemporaryDirectory() {
        std::string pattern = (fs::temp_directory_path() / "roughscope-fuzz-curet-XXXXXX").string();
        if (mkdtemp(pattern.data()) == nullptr)
            throw std::runtime_error("cannot create a temporary directory");
        path_ = pattern;
    }
    ~TemporaryDirectory() {
        std::error_code ec;
        fs::remove_all(path_, ec);
    }
    TemporaryDirectory(const TemporaryDirectory&) = delete;
    TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;
    const fs::path& path() const { return path_; }

  private:
    fs::path path_;
};

const fs::path& work_directory() {
    static const TemporaryDirectory directory;
    return directory.path();
}

void write_file(const fs::path& path, std::string_view content) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
    if (!out) throw std::runtime_error("cannot write " + path.string());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const fs::path& dir = work_directory();
    std::string_view rest = roughscope::fuzz::as_text(data, size);
    for (const char* name : kFileNames) {
        const std::size_t end = rest.find(kSeparator);
        const std::string_view part = rest.substr(0, end);
        rest = end == std::string_view::npos ? std::string_view() : rest.substr(end + 1);
        std::error_code ec;
        fs::remove(dir / name, ec);
        if (!part.empty()) write_file(dir / name, part);
    }
    roughscope::fuzz::expect_only_roughscope_errors([&] {
        const roughscope::CuretDatabase db = roughscope::load_curet(dir);
        for (const int sample : db.samples) (void)db.sample_table(sample);
    });
    return 0;
}
