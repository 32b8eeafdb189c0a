#include "pwl/study/sweep_journal.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>

#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include "pwl/errors.hpp"
#include "pwl/study/indicators.hpp"

namespace pwl::analysis {
namespace {

std::uint64_t fnv1a(std::string_view text) {
  std::uint64_t h = 14695981039346656037ull;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
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
  return fmt::format("{} {:016x} {}\n", id, fnv1a(payload), payload);
}

std::optional<std::pair<long, PointResult>> decode_record(std::string_view line) {
  if (!line.empty() && line.back() == '\n') line.remove_suffix(1);
  const std::size_t a = line.find(' ');
  if (a == std::string_view::npos) return std::nullopt;
  const std::size_t b = line.find(' ', a + 1);
  if (b == std::string_view::npos || b - a - 1 != 16) return std::nullopt;
  const std::string_view payload = line.substr(b + 1);
  if (fmt::format("{:016x}", fnv1a(payload)) != line.substr(a + 1, 16)) return std::nullopt;
  long id = 0;
  {
    Tokens t(line.substr(0, a));
    if (!t.integer(&id) || !t.done()) return std::nullopt;
  }
  Tokens t(payload);
  PointResult r;
  for (const Indicator& indicator : indicators()) {
    if (indicator.derived) continue;
    std::string_view token;
    if (!t.next(&token) || !read_indicator_token(indicator, token, r)) return std::nullopt;
  }
  long columns = 0, count = 0, state = 0;
  if (!t.integer(&columns) || !t.integer(&count) || columns < 0 || count < 0 ||
      (columns == 0 && count != 0) || (columns > 0 && count % columns != 0)) {
    return std::nullopt;
  }
  r.columns = static_cast<int>(columns);
  r.poincare.resize(static_cast<std::size_t>(count));
  for (double& v : r.poincare)
    if (!t.number(&v)) return std::nullopt;
  if (!t.integer(&state) || state < 0) return std::nullopt;
  r.final_state.resize(state);
  for (Index i = 0; i < state; ++i)
    if (!t.number(&r.final_state[i])) return std::nullopt;
  if (!t.done()) {
    long times = 0;
    if (!t.integer(&times) || times < 1 || (columns > 0 && times != count / columns)) {
      return std::nullopt;
    }
    r.section_times.resize(static_cast<std::size_t>(times));
    for (double& v : r.section_times)
      if (!t.number(&v)) return std::nullopt;
  }
  if (!t.done()) return std::nullopt;
  return std::make_pair(id, std::move(r));
}

SweepJournal::SweepJournal(const std::string& path, bool truncate_partial) : path_(path) {
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd_ < 0) throw Error(fmt::format("cannot open {} for appending: {}", path, std::strerror(errno)));
  if (truncate_partial) {
    std::ifstream in(path, std::ios::binary);
    const std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::size_t last = content.rfind('\n');
    const std::size_t keep = last == std::string::npos ? 0 : last + 1;
    if (keep != content.size() && ::ftruncate(fd_, static_cast<off_t>(keep)) != 0) {
      throw Error(fmt::format("cannot cut the torn last line of {}: {}", path, std::strerror(errno)));
    }
  }
}

SweepJournal::~SweepJournal() {
  if (fd_ >= 0) ::close(fd_);
}

void SweepJournal::append(long id, const PointResult& result) {
  const std::string line = encode_record(id, result);
  std::size_t written = 0;
  while (written < line.size()) {
    const ssize_t w = ::write(fd_, line.data() + written, line.size() - written);
    if (w < 0) {
      if (errno == EINTR) continue;
      throw Error(fmt::format("cannot append to {}: {}", path_, std::strerror(errno)));
    }
    written += static_cast<std::size_t>(w);
  }
}

std::map<long, PointResult> read_journal(const std::string& path) {
  std::map<long, PointResult> records;
  std::ifstream in(path, std::ios::binary);
  if (!in) return records;
  const std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::size_t start = 0;
  while (start < content.size()) {
    const std::size_t end = content.find('\n', start);
    if (end == std::string::npos) break;  // a torn last line: not trusted
    if (auto record = decode_record(std::string_view(content).substr(start, end - start))) {
      records.emplace(record->first, std::move(record->second));
    }
    start = end + 1;
  }
  return records;
}

}  // namespace pwl::analysis
