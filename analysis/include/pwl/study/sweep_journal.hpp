#pragma once
// The append-only record of a long parameter study, from which a run that was killed resumes.
//
// Every finished point is appended as one line, written by a single write(2) on a file opened
// with O_APPEND, so that a process killed at any moment (even by SIGKILL, which no handler sees)
// leaves at most one partial line at the end. A line is
//
//     <id> <checksum> <payload>\n
//
// where the payload is the point's indicators in the order of their table (indicators.hpp; the
// derived ones left out), then the number of columns and of values of its Poincaré points, the
// values, the size of its final state and its entries, for a hyperplane section the number of
// its points' times and the times (left out when there are none), all separated by single
// blanks, and the checksum is the 64-bit FNV-1a hash of the payload (Fowler, Noll & Vo; see
// draft-eastlake-fnv) in hexadecimal. A reader trusts a line only when it ends with a newline,
// parses completely and its checksum matches, so a torn or garbled line is dropped and its point
// computed again. Doubles are written with 17 significant digits, which read back as the same
// double, so a continuation that resumes from a recorded final state follows exactly the path an
// uninterrupted run would have.
#include <map>
#include <optional>
#include <string>
#include <string_view>

#include "pwl/study/sweep_point.hpp"

namespace pwl::analysis {

// One line (with its newline) for point `id`.
std::string encode_record(long id, const PointResult& result);
// The record of one line (without or with its newline), or nullopt when the line is torn, does not
// parse or fails its checksum.
std::optional<std::pair<long, PointResult>> decode_record(std::string_view line);

class SweepJournal {
 public:
  // Opens (creating it if needed) `path` for appending. When `truncate_partial` is set, a torn
  // last line (bytes after the last newline) left by a killed run is cut off first, so that the
  // next record starts on a line of its own. Throws pwl::Error when the file cannot be opened.
  SweepJournal(const std::string& path, bool truncate_partial);
  ~SweepJournal();
  SweepJournal(const SweepJournal&) = delete;
  SweepJournal& operator=(const SweepJournal&) = delete;

  // Appends one record with one write(2). Not thread-safe: callers serialise.
  void append(long id, const PointResult& result);

 private:
  int fd_ = -1;
  std::string path_;
};

// Every valid record of the file at `path` (none when it does not exist), by id; of duplicates the
// first is kept.
std::map<long, PointResult> read_journal(const std::string& path);

}  // namespace pwl::analysis
