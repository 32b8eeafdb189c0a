// The journal of a parameter study: records read back exactly, and torn or garbled lines (what a
// SIGKILL in the middle of a write leaves) are rejected.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>

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
