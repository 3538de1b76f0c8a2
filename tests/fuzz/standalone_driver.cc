// Runs a libFuzzer-style target without libFuzzer, so fuzz targets build with g++ and run under
// ctest with the sanitizers: replays every file of the corpus directories given, then
// --iterations deterministic mutations of them (bit flips, byte sets, truncations, insertions,
// splices with another input). Deterministic: the same corpus gives the same inputs every run.
// A crash or sanitizer report fails the test; the input that caused it is the last one written
// to stderr with --verbose, and can be added to the corpus as a regression case.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace {

using Bytes = std::vector<uint8_t>;

Bytes read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void run(const Bytes& input) {
  // Copy into an exactly sized heap block so ASan catches reads one past the end.
  uint8_t* copy = static_cast<uint8_t*>(std::malloc(input.empty() ? 1 : input.size()));
  if (!input.empty()) std::memcpy(copy, input.data(), input.size());
  LLVMFuzzerTestOneInput(copy, input.size());
  std::free(copy);
}

Bytes mutate(const Bytes& base, const Bytes& other, std::mt19937_64& rng) {
  Bytes out = base;
  const int edits = 1 + static_cast<int>(rng() % 4);
  for (int e = 0; e < edits; ++e) {
    const size_t n = out.size();
    switch (rng() % 7) {
      case 0:  // flip one bit
        if (n) out[rng() % n] ^= static_cast<uint8_t>(1u << (rng() % 8));
        break;
      case 1:  // set a byte to an interesting value
        if (n) {
          static const uint8_t kValues[] = {0x00, 0x01, 0x7f, 0x80, 0xfe, 0xff};
          out[rng() % n] = kValues[rng() % sizeof kValues];
        }
        break;
      case 2:  // set a 32-bit little-endian word to an extreme
        if (n >= 4) {
          static const uint32_t kWords[] = {0, 1, 0x7fffffff, 0x80000000, 0xffffffff, 0x10000};
          const uint32_t w = kWords[rng() % 6];
          std::memcpy(&out[rng() % (n - 3)], &w, 4);
        }
        break;
      case 3:  // truncate
        if (n) out.resize(rng() % n);
        break;
      case 4:  // insert random bytes
      {
        const size_t at = n ? rng() % (n + 1) : 0;
        const size_t count = 1 + rng() % 16;
        Bytes ins(count);
        for (auto& b : ins) b = static_cast<uint8_t>(rng());
        out.insert(out.begin() + static_cast<std::ptrdiff_t>(at), ins.begin(), ins.end());
        break;
      }
      case 5:  // randomise a byte
        if (n) out[rng() % n] = static_cast<uint8_t>(rng());
        break;
      case 6:  // splice: our prefix + the other input's suffix
        if (n && !other.empty()) {
          const size_t cut = rng() % n;
          const size_t from = rng() % other.size();
          out.resize(cut);
          out.insert(out.end(), other.begin() + static_cast<std::ptrdiff_t>(from), other.end());
        }
        break;
    }
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  long iterations = 1000;
  bool verbose = false;
  std::vector<Bytes> corpus;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--iterations" && i + 1 < argc) {
      iterations = std::strtol(argv[++i], nullptr, 10);
    } else if (arg == "--verbose") {
      verbose = true;
    } else if (std::filesystem::is_directory(arg)) {
      std::vector<std::filesystem::path> files;
      for (const auto& entry : std::filesystem::directory_iterator(arg))
        if (entry.is_regular_file()) files.push_back(entry.path());
      std::sort(files.begin(), files.end());  // directory order is not deterministic
      for (const auto& f : files) corpus.push_back(read_file(f));
    } else if (std::filesystem::is_regular_file(arg)) {
      corpus.push_back(read_file(arg));
    } else {
      std::fprintf(stderr, "fuzz driver: '%s' is neither a file nor a directory\n", arg.c_str());
      return 2;
    }
  }
  if (corpus.empty()) corpus.push_back(Bytes());
  for (const auto& input : corpus) run(input);
  std::mt19937_64 rng(0x63616c66);  // "calf"
  for (long i = 0; i < iterations; ++i) {
    const Bytes& base = corpus[rng() % corpus.size()];
    const Bytes& other = corpus[rng() % corpus.size()];
    const Bytes input = mutate(base, other, rng);
    if (verbose) std::fprintf(stderr, "input %ld: %zu bytes\n", i, input.size());
    run(input);
  }
  std::printf("fuzz driver: %zu corpus inputs, %ld mutations, no crash\n", corpus.size(),
              iterations);
  return 0;
}
