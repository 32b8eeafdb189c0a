#pragma once
// A small CSV writer: a header, then rows of doubles at full precision (17 significant digits,
// so a file read back gives the same numbers).
#include <cstdio>
#include <string>
#include <vector>

#include "pwl/types.hpp"

namespace pwl::app {

class CsvWriter {
 public:
  // Opens (truncates) the file and writes the header. Throws pwl::Error when it cannot.
  CsvWriter(const std::string& path, const std::vector<std::string>& columns);
  ~CsvWriter();
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;

  // One row: t, then the entries of each vector in order.
  void row(double t, const Vector& a, const Vector& b = Vector());
  void row(const std::vector<double>& values);

 private:
  std::FILE* file_;
  std::string path_;
};

// A CSV file written a row of text at a time and flushed after each, so that a run that is
// interrupted keeps every row it wrote, whole. Throws pwl::Error naming the file when it cannot
// open or write it.
class FlushedCsv {
 public:
  FlushedCsv(const std::string& path, const std::vector<std::string>& columns);
  ~FlushedCsv();
  FlushedCsv(const FlushedCsv&) = delete;
  FlushedCsv& operator=(const FlushedCsv&) = delete;
  void row(const std::string& text);
  long rows() const { return rows_; }

 private:
  std::FILE* file_;
  std::string path_;
  long rows_ = 0;
};

// `value` with 17 significant digits: read back, the same double.
std::string full_precision(double value);

// "x1".."xn" followed by "v1".."vn".
std::vector<std::string> state_columns(const std::string& first, Index n);

}  // namespace pwl::app
