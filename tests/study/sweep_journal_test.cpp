// The journal of a parameter study: records read back exactly; torn or garbled lines (what a
// SIGKILL in the middle of a write leaves) are rejected, and damaged lines anywhere are named by
// their number; foreign and conflicting records are refused; a write that does not fit leaves
// whole lines.
#include <sys/resource.h>

#include <catch2/catch.hpp>
#include <fmt/format.h>

#include <csignal>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>

#include "pwl/errors.hpp"
#include "pwl/study/sweep_journal.hpp"

using namespace pwl;
using namespace pwl::analysis;

namespace {

PointResult sample_result() {
  PointResult r;
  r.regime = "period-2";
  r.period = 2;
  r.lambda1 = -0.1234567890123456789;
  r.lambda1_error = 3e-300;
  r.K = std::numeric_limits<double>::quiet_NaN();
  r.columns = 2;
  r.poincare = {0.1, -1.0 / 3.0, 2.0 / 7.0, std::nextafter(1.0, 2.0)};
  r.final_state = Vector::LinSpaced(4, -1.0 / 9.0, 5.0 / 11.0);
  return r;
}

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / name).string();
}

}  // namespace

TEST_CASE("a record reads back bit for bit", "[sweep_journal]") {
  const PointResult r = sample_result();
  const std::string line = encode_record(42, r);
  REQUIRE(line.back() == '\n');
  const auto back = decode_record(line);
  REQUIRE(back.has_value());
  CHECK(back->first == 42);
  const PointResult& b = back->second;
  CHECK(b.regime == r.regime);
  CHECK(b.period == 2);
  CHECK(b.lambda1 == r.lambda1);
  CHECK(b.lambda1_error == r.lambda1_error);
  CHECK(std::isnan(b.K));
  CHECK(b.columns == 2);
  CHECK(b.poincare == r.poincare);
  CHECK(b.final_state == r.final_state);
  CHECK(b.rows() == 2);
}

TEST_CASE("torn and altered lines are rejected", "[sweep_journal]") {
  const std::string line = encode_record(7, sample_result());
  for (std::size_t cut : {std::size_t{1}, std::size_t{5}, std::size_t{20}, line.size() / 2,
                          line.size() - 3}) {
    CHECK_FALSE(decode_record(line.substr(0, cut)).has_value());
  }
  std::string altered = line;
  altered[altered.size() - 4] = altered[altered.size() - 4] == '1' ? '2' : '1';
  CHECK_FALSE(decode_record(altered).has_value());
  CHECK_FALSE(decode_record("").has_value());
  CHECK_FALSE(decode_record("garbage\n").has_value());
}

TEST_CASE("a torn last line is cut off before appending and skipped when reading",
          "[sweep_journal]") {
  const std::string path = temp_path("pwl_sweep_journal_test.log");
  std::filesystem::remove(path);
  {
    SweepJournal journal(path, true);
    journal.append(1, sample_result());
    journal.append(2, sample_result());
  }
  // A third record killed halfway through its write.
  const std::string third = encode_record(3, sample_result());
  {
    std::ofstream out(path, std::ios::binary | std::ios::app);
    out << third.substr(0, third.size() / 2);
  }
  auto records = read_journal(path);
  CHECK(records.size() == 2);
  CHECK(records.count(1) == 1);
  CHECK(records.count(2) == 1);
  {
    SweepJournal journal(path, true);  // cuts the torn line
    journal.append(3, sample_result());
  }
  records = read_journal(path);
  REQUIRE(records.size() == 3);
  CHECK(records.at(3).poincare == sample_result().poincare);
  std::filesystem::remove(path);
  CHECK(read_journal(path).empty());
}

namespace {

// A journal of points 0..count-1 at `path`, written as a study writes it.
void write_journal(const std::string& path, long count) {
  std::filesystem::remove(path);
  SweepJournal journal(path, true);
  for (long id = 0; id < count; ++id) {
    PointResult r = sample_result();
    r.poincare[0] = static_cast<double>(id);
    journal.append(id, r);
  }
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
}

// The offset of the first byte of 1-based line `line`.
std::size_t line_start(const std::string& text, int line) {
  std::size_t at = 0;
  for (int l = 1; l < line; ++l) at = text.find('\n', at) + 1;
  return at;
}

bool is_point_of_ten(long id) { return id >= 0 && id < 10; }

}  // namespace

TEST_CASE("a damaged line anywhere is found by its checksum and named by its number",
          "[sweep_journal]") {
  const std::string path = temp_path("pwl_sweep_journal_damage.log");
  write_journal(path, 10);
  std::string text = read_text(path);
  // Line 3: one byte of a value; line 5: one digit of the checksum; line 7: the id (7 -> 9, an
  // id the study has, whose record is elsewhere in the file).
  const std::size_t value = line_start(text, 3) + 40;
  text[value] = text[value] == '5' ? '6' : '5';
  const std::size_t checksum = line_start(text, 5) + 2;
  text[checksum] = text[checksum] == 'a' ? 'b' : 'a';
  const std::size_t id = line_start(text, 7);
  REQUIRE(text[id] == '6');  // line 7 holds point 6
  text[id] = '9';
  write_text(path, text);

  const JournalFile file = read_journal_file(path);
  REQUIRE(file.damaged.size() == 3);
  CHECK(file.damaged[0].line == 3);
  CHECK(file.damaged[1].line == 5);
  CHECK(file.damaged[2].line == 7);
  for (const DamagedLine& d : file.damaged) CHECK(d.reason == "its checksum does not match its contents");
  CHECK(file.records.size() == 7);
  CHECK(file.torn_bytes == 0);

  const StudyJournals study = read_study_journals({path}, is_point_of_ten);
  // Points 2, 4 and 6 are left to be computed again; 9 keeps its own record.
  CHECK(study.records.size() == 7);
  for (long missing : {2L, 4L, 6L}) CHECK(study.records.count(missing) == 0);
  REQUIRE(study.records.count(9) == 1);
  CHECK(study.records.at(9).poincare[0] == 9.0);
  REQUIRE(study.warnings.size() == 3);
  CHECK(study.warnings[0] == path + " line 3 is damaged (its checksum does not match its "
                                    "contents): the line is ignored and its point computed again");
  CHECK_THAT(study.warnings[2], Catch::StartsWith(path + " line 7 is damaged"));
  CHECK(study.notes.empty());
  std::filesystem::remove(path);
}

TEST_CASE("only the spelling pwl writes is trusted", "[sweep_journal]") {
  std::string why;
  CHECK_FALSE(decode_record("12\n", &why).has_value());
  CHECK(why == "it has no checksum field");
  CHECK_FALSE(decode_record("12 abc period-1", &why).has_value());
  CHECK(why == "its second field is not a 16-digit checksum");
  // A line with a correct checksum but a number spelled otherwise ("1e0" for "1"), a leading zero
  // in the id or a doubled blank: not what pwl writes, so not trusted. Its checksum is computed
  // here as the journal computes it (FNV-1a of the id, a blank and the payload).
  const auto with_checksum = [](const std::string& id, const std::string& payload) {
    std::uint64_t h = 14695981039346656037ull;
    for (unsigned char c : id + " " + payload) {
      h ^= c;
      h *= 1099511628211ull;
    }
    return fmt::format("{} {:016x} {}\n", id, h, payload);
  };
  const std::string line = encode_record(5, sample_result());
  const std::string payload = line.substr(line.find(' ', line.find(' ') + 1) + 1);
  const std::string body = payload.substr(0, payload.size() - 1);
  REQUIRE(with_checksum("5", body) == line);  // the journal's own checksum, reproduced
  REQUIRE(decode_record(line, &why).has_value());
  for (const std::string& foreign :
       {with_checksum("05", body), with_checksum("5", body + " "),
        with_checksum("5", "period-2 2 -0.12345678901234568 3e-300 nan 2 4 0.1 "
                           "-0.33333333333333331 0.2857142857142857 1.0000000000000002 "
                           "4 -0.1111111111111111 0.077441077441077422 0.26599326599326598 "
                           "0.45454545454545453"),
        with_checksum("5", "period-2 2 -0.12345678901234568 3e-300 nan 2 4 1e-1 "
                           "-0.33333333333333331 0.2857142857142857 1.0000000000000002 "
                           "4 -0.1111111111111111 0.077441077441077422 0.26599326599326598 "
                           "0.45454545454545453"),
        with_checksum("5", "period-2 2 0 0 nan 1 999999999999 0")}) {
    INFO(foreign);
    CHECK_FALSE(decode_record(foreign, &why).has_value());
    CHECK(why == "its checksum matches, but it is not a record as pwl writes one");
  }
}

TEST_CASE("records of ids a study does not have, or two results for one point, are refused",
          "[sweep_journal]") {
  const std::string a = temp_path("pwl_sweep_journal_a.log");
  const std::string b = temp_path("pwl_sweep_journal_b.log");
  write_journal(a, 10);
  // The same records in a second file (a journal copied over another): kept once, no word.
  write_journal(b, 10);
  StudyJournals study = read_study_journals({a, b}, is_point_of_ten);
  CHECK(study.records.size() == 10);
  CHECK(study.warnings.empty());
  // Another result for point 4, on line 2 of b: both lines named.
  {
    SweepJournal journal(b, true);
    PointResult other = sample_result();
    other.regime = "chaotic";
    std::filesystem::resize_file(b, 0);
    PointResult same = sample_result();
    same.poincare[0] = 3.0;
    journal.append(3, same);
    journal.append(4, other);
  }
  CHECK_THROWS_WITH(read_study_journals({a, b}, is_point_of_ten),
                    a + " line 5 and " + b +
                        " line 2 are valid records of point 4 with different results: two runs "
                        "computed it differently (two processes resuming into one folder at once, "
                        "or another build of pwl), and which is right is unknown; delete the wrong "
                        "line, "
                        "or start over without --resume");
  CHECK_THROWS_AS(read_study_journals({a, b}, is_point_of_ten), InputError);
  // A valid record of point 12 in a study of points 0..9: the folder mixes studies.
  write_journal(b, 13);
  CHECK_THROWS_WITH(read_study_journals({a, b}, is_point_of_ten),
                    Catch::StartsWith(b + " line 11: a valid record of point 10, which is not a "
                                          "point of this study"));
  std::filesystem::remove(a);
  std::filesystem::remove(b);
}

TEST_CASE("a write that does not fit leaves the journal with whole lines", "[sweep_journal]") {
  const std::string path = temp_path("pwl_sweep_journal_full.log");
  std::filesystem::remove(path);
  const std::size_t line = encode_record(0, sample_result()).size();
  // A file size limit of two and a half lines, as ulimit -f sets one; SIGXFSZ ignored as pwl
  // ignores it, so that the third write fails with EFBIG after writing half a line.
  struct rlimit saved {};
  REQUIRE(getrlimit(RLIMIT_FSIZE, &saved) == 0);
  struct rlimit small = saved;
  small.rlim_cur = static_cast<rlim_t>(2 * line + line / 2);
  void (*previous)(int) = std::signal(SIGXFSZ, SIG_IGN);
  REQUIRE(setrlimit(RLIMIT_FSIZE, &small) == 0);
  std::string message;
  {
    SweepJournal journal(path, true);
    journal.append(0, sample_result());
    journal.append(1, sample_result());
    try {
      journal.append(2, sample_result());
    } catch (const Error& e) {
      message = e.what();
    }
  }
  REQUIRE(setrlimit(RLIMIT_FSIZE, &saved) == 0);
  std::signal(SIGXFSZ, previous);
  CHECK(message == "cannot append point 2 to " + path + ": File too large");
  CHECK(std::filesystem::file_size(path) == 2 * line);
  const JournalFile file = read_journal_file(path);
  CHECK(file.records.size() == 2);
  CHECK(file.damaged.empty());
  CHECK(file.torn_bytes == 0);
  std::filesystem::remove(path);
}

TEST_CASE("a torn last line longer than a block is cut, and a file of one torn line emptied",
          "[sweep_journal]") {
  const std::string path = temp_path("pwl_sweep_journal_long_tear.log");
  write_journal(path, 40);
  const auto whole = std::filesystem::file_size(path);
  {
    std::ofstream out(path, std::ios::binary | std::ios::app);
    out << std::string(10000, '7');  // no newline: two and a half blocks of a torn line
  }
  {
    SweepJournal journal(path, true);
    CHECK(journal.cut_bytes() == 10000);
  }
  CHECK(std::filesystem::file_size(path) == whole);
  CHECK(read_journal_file(path).records.size() == 40);
  write_text(path, std::string(9000, 'x'));
  {
    SweepJournal journal(path, true);
    CHECK(journal.cut_bytes() == 9000);
  }
  CHECK(std::filesystem::file_size(path) == 0);
  std::filesystem::remove(path);
}

TEST_CASE("reading stops when asked to, and says so", "[sweep_journal]") {
  const std::string path = temp_path("pwl_sweep_journal_stop.log");
  write_journal(path, 1000);
  long asked = 0;
  // Asked every 256 lines; yes the second time: 511 lines read.
  const JournalFile file = read_journal_file(path, [&] { return ++asked == 2; });
  CHECK(file.stopped);
  CHECK(asked == 2);
  CHECK(file.records.size() == 511);
  const StudyJournals study =
      read_study_journals({path, path}, [](long) { return true; }, [] { return true; });
  CHECK(study.stopped);
  CHECK_FALSE(read_study_journals({path}, [](long) { return true; }).stopped);
  std::filesystem::remove(path);
}
