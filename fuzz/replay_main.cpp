// Replays inputs through a fuzz target without libFuzzer (any compiler): every regular file of
// each directory given (not recursive, sorted by name), or each file given, is passed once to
// LLVMFuzzerTestOneInput. A directory that does not exist is reported and skipped (a target may
// have no regression files yet), but at least one input must be found.
//
//   fuzz_<target>_replay fuzz/corpus/<target> fuzz/regressions/<target>
//
// Exit 0 when every input ran; a crash, an escaped exception or a sanitizer report ends the
// process as it would end the fuzzer. Nothing is written.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

#include "fuzz_target.hpp"

namespace {

namespace fs = std::filesystem;

std::vector<std::uint8_t> read_bytes(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error("cannot read " + path.string());
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::cerr << "usage: " << argv[0] << " DIR_OR_FILE...\n";
        return 2;
    }
    std::vector<fs::path> inputs;
    for (int k = 1; k < argc; ++k) {
        const fs::path arg(argv[k]);
        std::error_code ec;
        if (fs::is_directory(arg, ec)) {
            std::vector<fs::path> files;
            for (const auto& entry : fs::directory_iterator(arg))
                if (entry.is_regular_file()) files.push_back(entry.path());
            std::sort(files.begin(), files.end());
            inputs.insert(inputs.end(), files.begin(), files.end());
        } else if (fs::is_regular_file(arg, ec)) {
            inputs.push_back(arg);
        } else {
            std::cout << "replay: " << arg.string() << " does not exist, skipped\n";
        }
    }
    if (inputs.empty()) {
        std::cerr << "replay: no input files found\n";
        return 1;
    }
    for (const fs::path& path : inputs) {
        const std::vector<std::uint8_t> bytes = read_bytes(path);
        std::cout << "replay: " << path.string() << " (" << bytes.size() << " bytes)" << std::endl;
        LLVMFuzzerTestOneInput(bytes.data(), bytes.size());
    }
    std::cout << "replay: " << inputs.size() << " inputs ran without a failure\n";
    return 0;
}
