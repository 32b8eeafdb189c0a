#include "arguments.hpp"

#include <pybind11/numpy.h>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <string_view>
#include <vector>

#include "pwl/errors.hpp"

namespace py = pybind11;

namespace pwl::python {
namespace {

// One item of a value: an int, a float or a string. Bools only where a flag takes them.
std::string item_text(const py::handle& value, const std::string& function,
                      const std::string& keyword) {
  if (py::isinstance<py::bool_>(value)) {
    throw py::type_error(fmt::format("{}(): {}={} is not a value for {} (True/False are for flags)",
                                     function, keyword, py::repr(value).cast<std::string>(),
                                     flag_of(keyword)));
  }
  if (py::isinstance<py::str>(value)) return value.cast<std::string>();
  // Python ints and NumPy integers (which have __index__ but are not int).
  if (py::hasattr(value, "__index__") && !py::isinstance<py::float_>(value)) {
    const auto integer = py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()));
    if (!integer) throw py::error_already_set();
    return py::str(integer).cast<std::string>();
  }
  if (py::isinstance<py::float_>(value) || py::hasattr(value, "__float__")) {
    const double number = value.cast<double>();
    return fmt::format("{:.17g}", number);
  }
  throw py::type_error(fmt::format("{}(): {}={}: expected a number, a string or a list of them",
                                   function, keyword, py::repr(value).cast<std::string>()));
}

// A flag that takes FROM:TO (--range, --x-range, ...), by the name every such flag has.
bool is_range_flag(const std::string& flag) {
  constexpr std::string_view kRange = "range";
  return flag.size() >= kRange.size() &&
         flag.compare(flag.size() - kRange.size(), kRange.size(), kRange) == 0;
}

bool is_list(const py::handle& value);

// A pair (name, (from, to)): a parameter and its range.
bool is_named_range(const py::handle& value) {
  if (!py::isinstance<py::tuple>(value) && !py::isinstance<py::list>(value)) return false;
  const py::sequence pair = py::reinterpret_borrow<py::sequence>(value);
  if (pair.size() != 2 || !py::isinstance<py::str>(pair[0]) || !is_list(pair[1])) return false;
  return py::len(pair[1]) == 2;
}

bool is_list(const py::handle& value) {
  return !py::isinstance<py::str>(value) && !py::isinstance<py::bytes>(value) &&
         (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value) ||
          py::isinstance<py::array>(value));
}

}  // namespace

std::string flag_of(const std::string& keyword) {
  std::string flag = "--" + keyword;
  std::replace(flag.begin(), flag.end(), '_', '-');
  return flag;
}

void leave_out(CLI::App& app, const LeftOut& left_out) {
  app.set_help_flag();  // no --help: help=True is not a keyword
  for (const auto& [flag, why] : left_out) {
    if (CLI::Option* option = app.get_option_no_throw(flag)) app.remove_option(option);
  }
}

void parse_keywords(CLI::App& app, const std::string& function, const py::dict& kwargs,
                    const LeftOut& left_out) {
  std::vector<std::string> args;
  for (const auto& [key, value] : kwargs) {
    const std::string keyword = key.cast<std::string>();
    const std::string flag = flag_of(keyword);
    const auto dropped = left_out.find(flag);
    if (dropped != left_out.end()) {
      throw py::type_error(fmt::format("{}() does not take {}=: {}", function, keyword,
                                       dropped->second));
    }
    // Keywords are spelt with underscores; **{"skip-periods": 1} names no keyword.
    const CLI::Option* option =
        keyword.find('-') == std::string::npos ? app.get_option_no_throw(flag) : nullptr;
    if (option == nullptr) {
      throw py::type_error(
          fmt::format("{}() got an unexpected keyword argument '{}'", function, keyword));
    }
    if (value.is_none()) continue;
    if (option->get_expected_max() == 0) {  // a flag
      if (!py::isinstance<py::bool_>(value)) {
        throw py::type_error(fmt::format("{}(): {} is a flag ({}): give True or False, not {}",
                                         function, keyword, flag,
                                         py::repr(value).cast<std::string>()));
      }
      if (value.cast<bool>()) args.push_back(flag);
      continue;
    }
    std::string text;
    if (is_named_range(value)) {
      // (NAME, (FROM, TO)): the command line's NAME=FROM:TO (--curves alpha=1:15).
      const py::sequence pair = py::reinterpret_borrow<py::sequence>(value);
      const py::list range = py::isinstance<py::array>(pair[1])
                                 ? py::list(pair[1].attr("tolist")())
                                 : py::list(py::reinterpret_borrow<py::object>(pair[1]));
      text = pair[0].cast<std::string>() + "=" + item_text(range[0], function, keyword) + ":" +
             item_text(range[1], function, keyword);
    } else if (is_range_flag(flag) && is_list(value)) {
      // (FROM, TO): the command line's FROM:TO.
      const py::list items = py::isinstance<py::array>(value)
                                 ? py::list(value.attr("tolist")())
                                 : py::list(py::reinterpret_borrow<py::object>(value));
      if (items.size() != 2) {
        throw py::type_error(fmt::format("{}(): {}={}: a range is two numbers, (FROM, TO)",
                                         function, keyword, py::repr(value).cast<std::string>()));
      }
      text = item_text(items[0], function, keyword) + ":" + item_text(items[1], function, keyword);
    } else if (is_list(value)) {
      const py::list items = py::isinstance<py::array>(value)
                                 ? py::list(value.attr("tolist")())
                                 : py::list(py::reinterpret_borrow<py::object>(value));
      if (items.empty()) continue;  // an empty list: not given
      std::vector<std::string> parts;
      for (const py::handle item : items) parts.push_back(item_text(item, function, keyword));
      text = fmt::format("{}", fmt::join(parts, ","));
    } else {
      text = item_text(value, function, keyword);
    }
    args.push_back(flag + "=" + text);
  }
  std::reverse(args.begin(), args.end());  // CLI11 parses a vector from its back
  try {
    app.parse(args);
  } catch (const CLI::ParseError& e) {
    throw InputError(e.what());
  }
}

std::vector<KeywordDoc> keyword_docs(const CLI::App& app) {
  std::vector<KeywordDoc> docs;
  for (const CLI::Option* option : app.get_options()) {
    const std::string& name = option->get_single_name();
    if (option->get_lnames().empty() || name == "help") continue;
    KeywordDoc doc;
    doc.keyword = name;
    std::replace(doc.keyword.begin(), doc.keyword.end(), '-', '_');
    doc.flag = option->get_expected_max() == 0;
    doc.default_text = doc.flag ? "False" : option->get_default_str();
    doc.description = option->get_description();
    docs.push_back(std::move(doc));
  }
  return docs;
}

namespace {
std::map<std::string, std::vector<KeywordDoc> (*)()>& keyword_registry() {
  static std::map<std::string, std::vector<KeywordDoc> (*)()> registry;
  return registry;
}
}  // namespace

void register_keywords(const std::string& function, std::vector<KeywordDoc> (*describe)()) {
  keyword_registry()[function] = describe;
}

std::vector<KeywordDoc> keywords_of(const std::string& function) {
  const auto found = keyword_registry().find(function);
  if (found == keyword_registry().end()) {
    throw InputError(fmt::format("no job named {}", function));
  }
  return found->second();
}

}  // namespace pwl::python
