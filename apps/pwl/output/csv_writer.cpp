#include "output/csv_writer.hpp"

#include <fmt/format.h>

#include "pwl/errors.hpp"

namespace pwl::app {

CsvWriter::CsvWriter(const std::string& path, const std::vector<std::string>& columns)
    : file_(std::fopen(path.c_str(), "w")), path_(path) {
  if (file_ == nullptr) throw Error(fmt::format("cannot write {}", path));
  fmt::print(file_, "{}\n", fmt::join(columns, ","));
}

CsvWriter::~CsvWriter() { std::fclose(file_); }

void CsvWriter::row(double t, const Vector& a, const Vector& b) {
  fmt::print(file_, "{:.17g}", t);
  for (Index i = 0; i < a.size(); ++i) fmt::print(file_, ",{:.17g}", a[i]);
  for (Index i = 0; i < b.size(); ++i) fmt::print(file_, ",{:.17g}", b[i]);
  std::fputc('\n', file_);
}

void CsvWriter::row(const std::vector<double>& values) {
  fmt::print(file_, "{:.17g}\n", fmt::join(values, ","));
}

FlushedCsv::FlushedCsv(const std::string& path, const std::vector<std::string>& columns)
    : file_(std::fopen(path.c_str(), "w")), path_(path) {
  if (file_ == nullptr) throw Error(fmt::format("cannot write {}", path));
  fmt::print(file_, "{}\n", fmt::join(columns, ","));
  if (std::fflush(file_) != 0) throw Error(fmt::format("cannot write {}", path_));
}

FlushedCsv::~FlushedCsv() {
  if (file_ != nullptr) std::fclose(file_);
}

void FlushedCsv::row(const std::string& text) {
  fmt::print(file_, "{}\n", text);
  if (std::fflush(file_) != 0) throw Error(fmt::format("cannot write {}", path_));
  ++rows_;
}

std::string full_precision(double value) { return fmt::format("{:.17g}", value); }

std::vector<std::string> state_columns(const std::string& first, Index n) {
  std::vector<std::string> columns{first};
  for (Index i = 1; i <= n; ++i) columns.push_back(fmt::format("x{}", i));
  for (Index i = 1; i <= n; ++i) columns.push_back(fmt::format("v{}", i));
  return columns;
}

}  // namespace pwl::app
