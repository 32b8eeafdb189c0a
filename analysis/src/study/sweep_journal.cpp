#include "pwl/study/sweep_journal.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <vector>

#include "pwl/errors.hpp"
#include "pwl/study/indicators.hpp"

namespace pwl::analysis {
namespace {

constexpr std::uint64_t kFnvOffset = 14695981039346656037ull;

std::uint64_t fnv1a(std::string_view text, std::uint64_t h = kFnvOffset) {
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

// The checksum of a line: the id's text, one blank, the payload.
std::uint64_t line_checksum(std::string_view id, std::string_view payload) {
  return fnv1a(payload, fnv1a(" ", fnv1a(id)));
}

void put(std::string& out, double v) { fmt::format_to(std::back_inserter(out), " {:.17g}", v); }

// Reads whitespace-separated tokens from a payload.
class Tokens {
 public:
  explicit Tokens(std::string_view text) : text_(text) {}
  bool next(std::string_view* token) {
    while (pos_ < text_.size() && text_[pos_] == ' ') ++pos_;
    if (pos_ >= text_.size()) return false;
    const std::size_t start = pos_;
    while (pos_ < text_.size() && text_[pos_] != ' ') ++pos_;
    *token = text_.substr(start, pos_ - start);
    return true;
  }
  bool number(double* v) {
    std::string_view t;
    if (!next(&t)) return false;
    const std::string s(t);
    char* end = nullptr;
    *v = std::strtod(s.c_str(), &end);
    return end == s.c_str() + s.size() && !s.empty();
  }
  bool integer(long* v) {
    std::string_view t;
    if (!next(&t)) return false;
    const std::string s(t);
    char* end = nullptr;
    errno = 0;
    *v = std::strtol(s.c_str(), &end, 10);
    return errno == 0 && end == s.c_str() + s.size() && !s.empty();
  }
  bool done() {
    while (pos_ < text_.size() && text_[pos_] == ' ') ++pos_;
    return pos_ == text_.size();
  }
  // At most this many more tokens can follow (each takes a blank and a character): a count read
  // from a damaged line is checked against it before anything is allocated.
  std::size_t most_tokens_left() const { return (text_.size() - pos_ + 1) / 2; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
};

}  // namespace

std::string encode_record(long id, const PointResult& r) {
  // The indicators in the table's order (their tokens are blank-free), then the Poincaré points and
  // the final state.
  std::string payload = indicator_tokens(r).substr(1);
  fmt::format_to(std::back_inserter(payload), " {} {}", r.columns, r.poincare.size());
  for (double v : r.poincare) put(payload, v);
  fmt::format_to(std::back_inserter(payload), " {}", r.final_state.size());
  for (Index i = 0; i < r.final_state.size(); ++i) put(payload, r.final_state[i]);
  // The times of a hyperplane section's points, only when there are any: a stroboscopic point's
  // line reads as it did before sections were chosen.
  if (!r.section_times.empty()) {
    fmt::format_to(std::back_inserter(payload), " {}", r.section_times.size());
    for (double t : r.section_times) put(payload, t);
  }
  const std::string id_text = fmt::format("{}", id);
  return fmt::format("{} {:016x} {}\n", id_text, line_checksum(id_text, payload), payload);
}

std::optional<std::pair<long, PointResult>> decode_record(std::string_view line, std::string* why) {
  const auto refuse = [why](const char* reason) {
    if (why != nullptr) *why = reason;
    return std::nullopt;
  };
  if (!line.empty() && line.back() == '\n') line.remove_suffix(1);
  const std::size_t a = line.find(' ');
  if (a == std::string_view::npos) return refuse("it has no checksum field");
  const std::size_t b = line.find(' ', a + 1);
  if (b == std::string_view::npos || b - a - 1 != 16) {
    return refuse("its second field is not a 16-digit checksum");
  }
  const std::string_view id_text = line.substr(0, a);
  const std::string_view payload = line.substr(b + 1);
  if (fmt::format("{:016x}", line_checksum(id_text, payload)) != line.substr(a + 1, 16)) {
    return refuse("its checksum does not match its contents");
  }
  // The checksum matches: from here on only a line that pwl did not write can fail.
  const char* foreign = "its checksum matches, but it is not a record as pwl writes one";
  long id = 0;
  {
    Tokens t(id_text);
    if (!t.integer(&id) || !t.done()) return refuse(foreign);
  }
  Tokens t(payload);
  PointResult r;
  for (const Indicator& indicator : indicators()) {
    if (indicator.derived) continue;
    std::string_view token;
    if (!t.next(&token) || !read_indicator_token(indicator, token, r)) return refuse(foreign);
  }
  long columns = 0, count = 0, state = 0;
  if (!t.integer(&columns) || !t.integer(&count) || columns < 0 || count < 0 ||
      columns > std::numeric_limits<int>::max() ||
      static_cast<unsigned long>(count) > t.most_tokens_left() || (columns == 0 && count != 0) ||
      (columns > 0 && count % columns != 0)) {
    return refuse(foreign);
  }
  r.columns = static_cast<int>(columns);
  r.poincare.resize(static_cast<std::size_t>(count));
  for (double& v : r.poincare)
    if (!t.number(&v)) return refuse(foreign);
  if (!t.integer(&state) || state < 0 || static_cast<unsigned long>(state) > t.most_tokens_left()) {
    return refuse(foreign);
  }
  r.final_state.resize(state);
  for (Index i = 0; i < state; ++i)
    if (!t.number(&r.final_state[i])) return refuse(foreign);
  if (!t.done()) {
    long times = 0;
    if (!t.integer(&times) || times < 1 || (columns > 0 && times != count / columns) ||
        static_cast<unsigned long>(times) > t.most_tokens_left()) {
      return refuse(foreign);
    }
    r.section_times.resize(static_cast<std::size_t>(times));
    for (double& v : r.section_times)
      if (!t.number(&v)) return refuse(foreign);
  }
  if (!t.done()) return refuse(foreign);
  // Only the one spelling encode_record writes is trusted ("1e0" for "1", a leading zero, a
  // doubled blank are not), so that a record that is read writes back as the same line.
  std::string again = encode_record(id, r);
  again.pop_back();
  if (again != line) return refuse(foreign);
  return std::make_pair(id, std::move(r));
}

SweepJournal::SweepJournal(const std::string& path, bool truncate_partial) : path_(path) {
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd_ < 0) throw Error(fmt::format("cannot open {} for appending: {}", path, std::strerror(errno)));
  if (truncate_partial) {
    // The last newline, looked for backwards from the end a block at a time (a journal may be
    // large; a torn line is one line at most).
    const auto fail = [&](const char* what) {
      const int error = errno;
      ::close(fd_);
      fd_ = -1;
      return Error(fmt::format("cannot {} {}: {}", what, path, std::strerror(error)));
    };
    struct stat st {};
    if (::fstat(fd_, &st) != 0) throw fail("read");
    const int reader = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (reader < 0) throw fail("read");
    off_t end = st.st_size, keep = 0;
    char block[4096];
    while (end > 0) {
      const off_t from = std::max<off_t>(0, end - static_cast<off_t>(sizeof block));
      const ssize_t got = ::pread(reader, block, static_cast<std::size_t>(end - from), from);
      if (got != end - from) {
        ::close(reader);
        throw fail("read");
      }
      const void* newline = ::memrchr(block, '\n', static_cast<std::size_t>(got));
      if (newline != nullptr) {
        keep = from + (static_cast<const char*>(newline) - block) + 1;
        break;
      }
      end = from;
    }
    ::close(reader);
    if (keep != st.st_size) {
      if (::ftruncate(fd_, keep) != 0) throw fail("cut the torn last line of");
      cut_ = static_cast<std::size_t>(st.st_size - keep);
    }
  }
}

SweepJournal::~SweepJournal() {
  if (fd_ >= 0) ::close(fd_);
}

void SweepJournal::append(long id, const PointResult& result) {
  const std::string line = encode_record(id, result);
  // Where the line begins: O_APPEND writes at the end, and this process is the file's only writer.
  const off_t start = ::lseek(fd_, 0, SEEK_END);
  std::size_t written = 0;
  while (written < line.size()) {
    const ssize_t w = ::write(fd_, line.data() + written, line.size() - written);
    if (w < 0) {
      if (errno == EINTR) continue;
      const int error = errno;
      // A part of the line may be in the file (the bytes that still fitted): cut it off, so that
      // the journal ends with a whole line. Should that fail too, the next run cuts the torn line.
      if (written > 0 && start >= 0) (void)!::ftruncate(fd_, start);
      throw Error(fmt::format("cannot append point {} to {}: {}", id, path_,
                              std::strerror(error)));
    }
    written += static_cast<std::size_t>(w);
  }
}

JournalFile read_journal_file(const std::string& path, const ReadStop& stop) {
  JournalFile file;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int error = errno;
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) return file;
    throw Error(fmt::format("cannot read {}: {}", path, std::strerror(error)));
  }
  const std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw Error(fmt::format("cannot read {}: {}", path, std::strerror(errno)));
  std::size_t start = 0;
  long number = 0;
  while (start < content.size()) {
    const std::size_t end = content.find('\n', start);
    if (end == std::string::npos) {  // a torn last line: not trusted
      file.torn_bytes = content.size() - start;
      break;
    }
    ++number;
    if (stop && number % 256 == 0 && stop()) {
      file.stopped = true;
      break;
    }
    const std::string_view line = std::string_view(content).substr(start, end - start);
    std::string why;
    if (auto record = decode_record(line, &why)) {
      // The checksum is the line's second field, 16 hexadecimal digits (decode_record checked).
      const std::size_t a = line.find(' ');
      const std::uint64_t checksum =
          std::strtoull(std::string(line.substr(a + 1, 16)).c_str(), nullptr, 16);
      file.records.push_back({number, record->first, checksum, std::move(record->second)});
    } else {
      file.damaged.push_back({number, std::move(why)});
    }
    start = end + 1;
  }
  return file;
}

std::map<long, PointResult> read_journal(const std::string& path) {
  std::map<long, PointResult> records;
  for (JournalRecord& r : read_journal_file(path).records) {
    records.emplace(r.id, std::move(r.result));
  }
  return records;
}

StudyJournals read_study_journals(const std::vector<std::string>& paths,
                                  const std::function<bool(long id)>& is_point,
                                  const ReadStop& stop) {
  StudyJournals study;
  // Where each id's record was read: its file, line and checksum.
  struct Seen {
    const std::string* path;
    long line;
    std::uint64_t checksum;
  };
  std::map<long, Seen> seen;
  for (const std::string& path : paths) {
    JournalFile file = read_journal_file(path, stop);
    if (file.stopped) {
      study.stopped = true;
      break;
    }
    for (const DamagedLine& d : file.damaged) {
      study.warnings.push_back(fmt::format(
          "{} line {} is damaged ({}): the line is ignored and its point computed again", path,
          d.line, d.reason));
    }
    if (file.torn_bytes > 0) {
      study.notes.push_back(fmt::format(
          "{} ends with a torn line of {} bytes (a write cut short by a kill): ignored, its point "
          "computed again",
          path, file.torn_bytes));
    }
    for (JournalRecord& r : file.records) {
      if (!is_point(r.id)) {
        throw InputError(fmt::format(
            "{} line {}: a valid record of point {}, which is not a point of this study: the "
            "folder mixes the journals of different studies, so none can be trusted; start over "
            "without --resume",
            path, r.line, r.id));
      }
      const auto [where, fresh] = seen.emplace(r.id, Seen{&path, r.line, r.checksum});
      if (fresh) {
        study.records.emplace(r.id, std::move(r.result));
      } else if (where->second.checksum != r.checksum) {
        throw InputError(fmt::format(
            "{} line {} and {} line {} are valid records of point {} with different results: two "
            "runs computed it differently (two processes resuming into one folder at once, or "
            "another build of pwl), and which is right is unknown; delete the wrong line, or start "
            "over without --resume",
            *where->second.path, where->second.line, path, r.line, r.id));
      }
    }
  }
  return study;
}

}  // namespace pwl::analysis
