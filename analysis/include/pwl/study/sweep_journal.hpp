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
// blanks, and the checksum is the 64-bit FNV-1a hash (Fowler, Noll & Vo; see draft-eastlake-fnv),
// in hexadecimal, of the id, one blank and the payload: a damaged id fails it as a damaged value
// does. (The first journals hashed the payload alone; config.txt records the format, so a folder
// of that format is refused by --resume instead of misread.) Doubles are written with 17
// significant digits, which read back as the same double, so a continuation that resumes from a
// recorded final state follows exactly the path an uninterrupted run would have.
//
// A reader trusts a line only when it ends with a newline, its checksum matches and it is exactly
// the line encode_record writes for what it decodes to (no other spelling of a number, no extra
// blank), so decode and encode are inverse on every line that is trusted. Anything else, anywhere
// in the file, is a damaged line: read_journal_file reports it by its line number and the study's
// reader (read_study_journals) leaves its point to be computed again.
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pwl/study/sweep_point.hpp"

namespace pwl::analysis {

// One line (with its newline) for point `id`.
std::string encode_record(long id, const PointResult& result);
// The record of one line (without or with its newline), or nullopt when the line is torn, does not
// parse, fails its checksum or is not spelled as encode_record spells it; then `why`, when given,
// says which ("its checksum does not match its contents", ...).
std::optional<std::pair<long, PointResult>> decode_record(std::string_view line,
                                                          std::string* why = nullptr);

class SweepJournal {
 public:
  // Opens (creating it if needed) `path` for appending. When `truncate_partial` is set, a torn
  // last line (bytes after the last newline) left by a killed run is cut off first, so that the
  // next record starts on a line of its own; cut_bytes() says how many bytes went. Throws
  // pwl::Error naming the path and the system's reason when the file cannot be opened or cut.
  SweepJournal(const std::string& path, bool truncate_partial);
  ~SweepJournal();
  SweepJournal(const SweepJournal&) = delete;
  SweepJournal& operator=(const SweepJournal&) = delete;

  // Appends one record with one write(2) (more only if the system writes it in parts). A write
  // that fails (a full disk: ENOSPC; a file size limit: EFBIG) after writing part of the line is
  // undone by cutting the file back to where the line began, so the journal keeps whole lines
  // only; then pwl::Error names the path, the point and the system's reason. Not thread-safe:
  // callers serialise.
  void append(long id, const PointResult& result);

  const std::string& path() const { return path_; }
  std::size_t cut_bytes() const { return cut_; }

 private:
  int fd_ = -1;
  std::string path_;
  std::size_t cut_ = 0;
};

// A line of a journal that is trusted: its 1-based number, its point and the line's checksum (one
// id with two checksums holds two different results).
struct JournalRecord {
  long line = 0;
  long id = 0;
  std::uint64_t checksum = 0;
  PointResult result;
};

// A line that is not trusted: its 1-based number and why.
struct DamagedLine {
  long line = 0;
  std::string reason;
};

// Every line of one journal file, sorted into trusted records and damaged lines, in file order.
// A torn last line (bytes after the last newline: a write cut short by a kill) is neither; its
// size is torn_bytes.
struct JournalFile {
  std::vector<JournalRecord> records;
  std::vector<DamagedLine> damaged;
  std::size_t torn_bytes = 0;
  bool stopped = false;  // `stop` said so before the end: what is above is a part of the file
};

// Asked now and then while a long journal is read (every 256 lines), so that a study told to stop
// (SIGINT, SIGTERM) while it reads its journals stops at once. Null: never stop.
using ReadStop = std::function<bool()>;

// Reads the journal at `path`: an empty JournalFile when it does not exist; pwl::Error naming the
// path and the system's reason when it exists and cannot be read.
JournalFile read_journal_file(const std::string& path, const ReadStop& stop = nullptr);

// Every valid record of the file at `path` (none when it does not exist), by id; of duplicates the
// first is kept. Damaged lines are left out without a word: a study reads its journals with
// read_study_journals, which reports them.
std::map<long, PointResult> read_journal(const std::string& path);

// The journals of one study (every journal file of its folder) read together.
//
//  - A damaged line anywhere in a file (not only a torn last one) is ignored, and named in a
//    warning "<path> line <n> is damaged (<reason>): ...": the point it held has no record then and
//    is computed again. Its id is not trusted (the checksum covers it), so it is never used.
//  - A torn last line is named in a note: what a kill during a write leaves, not damage.
//  - A trusted record of an id that is not a point of the study (`is_point` false) cannot have
//    been written by a run of this configuration, whose config.txt the folder holds: the folder
//    mixes studies, and its other records cannot be trusted either. Refused: InputError naming
//    the file, the line and the id.
//  - Two trusted records of one id: with the same checksum, the same result written twice (a
//    journal copied over another), kept once without a word. With different checksums, two runs
//    have computed the point differently (two processes resuming into one folder at once, or
//    another build): which one an uninterrupted run would have written is unknown, so both are
//    refused: InputError naming both lines.
//
// When `stop` says so, reading ends with `stopped` set; the records are then incomplete.
struct StudyJournals {
  std::map<long, PointResult> records;
  std::vector<std::string> warnings;  // damaged lines, one message each
  std::vector<std::string> notes;     // torn last lines, one message each
  bool stopped = false;
};
StudyJournals read_study_journals(const std::vector<std::string>& paths,
                                  const std::function<bool(long id)>& is_point,
                                  const ReadStop& stop = nullptr);

}  // namespace pwl::analysis
