// libFuzzer target for the journal reader (sweep_journal.hpp): any bytes, read as one line or as
// a whole journal file, must never crash, hang, allocate without bound or trip the sanitizers; a
// line that decodes must encode back to the very same bytes; reading a file must account for each
// of its lines (a record or a damaged line, numbered in order) and for its torn end; reading it as
// a study's journal may refuse it only with InputError. Built and run briefly by
// tests/study/journal_fuzz.cmake (clang only), seeded with journals of real sweeps and maps
// (tests/study/journal_corpus/).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string>
#include <string_view>

#include "pwl/errors.hpp"
#include "pwl/study/sweep_journal.hpp"

namespace pwl::analysis {

// The one function the two units under test (sweep_journal.cpp, indicators.cpp) name and do not
// define: the derived indicator "code" (sweep_point.cpp, which needs the whole integrator library).
// The journal never writes or reads derived indicators, so it must never be called: a call is a
// finding.
int regime_code(const std::string& /*regime*/, int /*period*/) { __builtin_trap(); }

}  // namespace pwl::analysis

namespace {

void require(bool condition) {
  if (!condition) __builtin_trap();
}

// `line` with its checksum field made right (FNV-1a of the id, a blank and the payload, as
// sweep_journal.hpp defines it), or empty when it has no such field. A mutated line almost never
// keeps a matching checksum by chance; this one gets past it, so that the parser behind it sees
// every mutation too (as fuzzers of PNG fix the chunks' CRCs).
std::string with_right_checksum(std::string_view line) {
  const std::size_t a = line.find(' ');
  if (a == std::string_view::npos) return {};
  const std::size_t b = line.find(' ', a + 1);
  if (b == std::string_view::npos || b - a - 1 != 16) return {};
  std::uint64_t h = 14695981039346656037ull;
  const auto hash = [&h](std::string_view part) {
    for (unsigned char c : part) {
      h ^= c;
      h *= 1099511628211ull;
    }
  };
  hash(line.substr(0, a));
  hash(" ");
  hash(line.substr(b + 1));
  static const char* digits = "0123456789abcdef";
  std::string fixed(line);
  for (int i = 15; i >= 0; --i, h >>= 4) fixed[a + 1 + static_cast<std::size_t>(i)] = digits[h & 15];
  return fixed;
}

// Decodes `line`; a record must encode back to the same bytes, a refusal must say why.
void check_line(std::string_view line) {
  std::string why;
  if (const auto record = pwl::analysis::decode_record(line, &why)) {
    require(pwl::analysis::encode_record(record->first, record->second) ==
            std::string(line) + "\n");
    require(why.empty());
  } else {
    require(!why.empty());
  }
}

const std::string& scratch_path() {
  static const std::string path = "journal_fuzz_" + std::to_string(::getpid()) + ".log";
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pwl::analysis;
  const std::string_view text(reinterpret_cast<const char*>(data), size);

  // Line by line, as read_journal_file splits a file.
  std::size_t lines = 0, start = 0;
  while (start < text.size()) {
    const std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) break;
    ++lines;
    const std::string_view line = text.substr(start, end - start);
    check_line(line);
    const std::string fixed = with_right_checksum(line);
    if (!fixed.empty()) {
      check_line(fixed);
      std::string why;
      // With its checksum right, a line is refused only for being no record pwl writes.
      if (!decode_record(fixed, &why)) {
        require(why == "its checksum matches, but it is not a record as pwl writes one");
      }
    }
    start = end + 1;
  }
  const std::size_t torn = text.size() - start;
  // The whole input without its newline splitting: also one line, torn or not.
  (void)decode_record(text);

  // As a journal file, and as a study's journal (points 0..63).
  {
    std::ofstream out(scratch_path(), std::ios::binary | std::ios::trunc);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
  }
  const JournalFile file = read_journal_file(scratch_path());
  require(file.records.size() + file.damaged.size() == lines);
  require(file.torn_bytes == torn);
  // Every line is a record or a damaged line, numbered in file order.
  std::size_t r = 0, d = 0;
  for (long line = 1; line <= static_cast<long>(lines); ++line) {
    if (r < file.records.size() && file.records[r].line == line) {
      ++r;
    } else {
      require(d < file.damaged.size() && file.damaged[d].line == line);
      ++d;
    }
  }
  try {
    const StudyJournals study =
        read_study_journals({scratch_path()}, [](long id) { return id >= 0 && id < 64; });
    require(study.warnings.size() == file.damaged.size());
    require(study.records.size() <= file.records.size());
  } catch (const pwl::InputError&) {
    // a foreign or conflicting record: refused with a message, the expected outcome
  }
  return 0;
}
