#include "scene/scene.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <sstream>

#include "pwl/errors.hpp"

namespace pwl::app {
namespace {

// Keys of [structure] that give a structure explicitly (scene_structure.hpp reads them).
bool is_explicit_structure_key(const std::string& key) {
  return key == "mass" || key == "damping" || key == "stiffness" || key == "spring" ||
         key == "load";
}

std::string where(const std::string& name, const toml::source_region& r) {
  return fmt::format("{}:{}:{}", name, r.begin.line, r.begin.column);
}

bool valid_key(const std::string& key) {
  return !key.empty() && std::all_of(key.begin(), key.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
  });
}

std::string flag_of(const std::string& section, const std::string& key) {
  if (section == "structure" && key == "masses") return "--n";
  if (section == "method" && key == "name") return "--method";
  std::string flag = fmt::format("--{}", key);
  std::replace(flag.begin(), flag.end(), '_', '-');
  return flag;
}

// A scalar as a flag argument; false when the node is not a scalar.
bool scalar_text(const toml::node& node, const std::string& at, const std::string& key,
                 std::string* text, SceneSetting::Kind* kind) {
  if (const auto* i = node.as_integer()) {
    *text = fmt::format("{}", i->get());
    *kind = SceneSetting::Kind::integer;
  } else if (const auto* d = node.as_floating_point()) {
    if (!std::isfinite(d->get())) {
      throw InputError(fmt::format("{}: {}: expected a finite number, got {}", at, key, d->get()));
    }
    *text = fmt::format("{}", d->get());
    *kind = SceneSetting::Kind::real;
  } else if (const auto* s = node.as_string()) {
    *text = s->get();
    *kind = SceneSetting::Kind::text;
  } else {
    return false;
  }
  return true;
}

const char* type_name(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "a list";
    case toml::node_type::string:
      return "text";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a number";
    case toml::node_type::boolean:
      return "true or false";
    default:
      return "a date or time";
  }
}

// One `key = value` of a section as a setting.
SceneSetting setting_of(const std::string& section, const std::string& key, const toml::node& node,
                        const std::string& at) {
  const std::string dotted = fmt::format("{}.{}", section, key);
  if (!valid_key(key)) {
    throw InputError(fmt::format(
        "{}: '{}': a key is lowercase letters, digits and '_' (the flag's name without '--')", at,
        dotted));
  }
  SceneSetting s;
  s.key = dotted;
  s.flag = flag_of(section, key);
  s.where = at;
  if (const auto* b = node.as_boolean()) {
    s.kind = SceneSetting::Kind::boolean;
    s.switched_on = b->get();
    return s;
  }
  std::string text;
  if (scalar_text(node, at, dotted, &text, &s.kind)) {
    s.values.push_back(std::move(text));
    return s;
  }
  if (const auto* list = node.as_array()) {
    if (list->empty())
      throw InputError(fmt::format("{}: {}: expected values, got an empty list", at, dotted));
    SceneSetting::Kind first = SceneSetting::Kind::text;
    for (std::size_t i = 0; i < list->size(); ++i) {
      SceneSetting::Kind kind;
      if (!scalar_text(*list->get(i), at, dotted, &text, &kind)) {
        throw InputError(
            fmt::format("{}: {}: element {} of the list is {}; expected a number or text", at,
                        dotted, i + 1, type_name(*list->get(i))));
      }
      const bool numeric = kind != SceneSetting::Kind::text;
      if (i > 0 && numeric != (first != SceneSetting::Kind::text)) {
        throw InputError(fmt::format("{}: {}: the list mixes numbers and text", at, dotted));
      }
      if (i == 0) first = kind;
      s.values.push_back(std::move(text));
    }
    s.kind = SceneSetting::Kind::list;
    return s;
  }
  throw InputError(fmt::format("{}: {}: expected a number, text, true/false or a list, got {}", at,
                               dotted, type_name(node)));
}

// The settings of one parsed document (a file, or one override).
void collect(const toml::table& doc, const std::string& name, bool is_override, Scene* scene) {
  for (auto&& [k, node] : doc) {
    const std::string section(k.str());
    const std::string at = is_override ? name : where(name, k.source());
    if (section == "job") {
      const auto* job = node.as_string();
      if (job == nullptr) {
        throw InputError(
            fmt::format("{}: job: expected text (simulate, analyze, sweep, map, orbit, continue or bench chain|scaling|accuracy|stability|sweep), got {}", at,
                        type_name(node)));
      }
      scene->job = job->get();
      continue;
    }
    const auto& sections = scene_sections();
    if (std::find(sections.begin(), sections.end(), section) == sections.end()) {
      throw InputError(fmt::format("{}: '{}': unknown {}; expected job or a section: {}", at,
                                   section, node.is_table() ? "section" : "top-level key",
                                   fmt::join(sections, ", ")));
    }
    const auto* table = node.as_table();
    if (table == nullptr) {
      throw InputError(fmt::format("{}: '{}' must be a section ([{}]), got {}", at, section,
                                   section, type_name(node)));
    }
    for (auto&& [key, value] : *table) {
      const std::string k2(key.str());
      const std::string at2 = is_override ? name : where(name, value.source());
      if (section == "structure" && is_explicit_structure_key(k2)) {
        if (is_override) {
          throw InputError(
              fmt::format("{}: structure.{} cannot be overridden; edit the scene file", name, k2));
        }
        scene->explicit_structure = true;
        continue;
      }
      if (value.is_table()) {
        throw InputError(fmt::format(
            "{}: {}.{}: sections do not nest; expected a value, got a table", at2, section, k2));
      }
      SceneSetting s = setting_of(section, k2, value, at2);
      s.position = static_cast<long>(value.source().begin.line) * 100000 +
                   static_cast<long>(value.source().begin.column);
      // An override replaces what the file says for the same flag.
      std::erase_if(scene->settings, [&](const SceneSetting& old) { return old.flag == s.flag; });
      scene->settings.push_back(std::move(s));
    }
  }
}

toml::table parse_toml(std::string_view text, const std::string& name) {
  const std::string screened = screen_scene_text(text, name);
  try {
    return toml::parse(screened, name);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}: {}", where(name, e.source()), e.description()));
  }
}

}  // namespace

std::string screen_scene_text(std::string_view text, const std::string& name) {
  std::string screened(text);
  enum class State { normal, comment, basic, literal, multi_basic, multi_literal };
  enum class Expect { nothing, value, element, key, key_or_end };
  State state = State::normal;
  Expect expect = Expect::nothing;
  std::vector<char> open;  // the [ and { of the value being read
  std::size_t line = 1, column = 1;
  bool line_start = true;  // nothing but blanks so far on this line
  bool in_header = false;  // inside a [section] header
  std::size_t i = text.substr(0, 3) == "\xEF\xBB\xBF" ? 3 : 0;  // a byte-order mark
  const auto starts = [&](std::string_view s) { return text.substr(i, s.size()) == s; };
  const auto fail = [&](std::string_view what) {
    throw InputError(fmt::format("{}:{}:{}: {}", name, line, column, what));
  };
  const auto key_start = [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-' || c == '"' || c == '\'';
  };
  // toml++ 3.3 reads a value of ten characters shaped like a date ("dddd-dd-dd", underscores not
  // counted) followed by a space as a date and time, and asserts instead of reporting when one
  // digit and the value's end follow the space ("m = 1979-05-27 1").
  const auto value_end = [](char c) {
    return std::string_view(" \t\r\n]},#").find(c) != std::string_view::npos;
  };
  const auto lone_time_digit = [&](std::size_t at) {
    std::array<char, 10> chars{};
    std::size_t count = 0, j = at;
    for (; j < text.size() && !value_end(text[j]); ++j) {
      if (text[j] == '_') continue;
      if (count == chars.size()) return false;
      chars[count++] = text[j];
    }
    return count == chars.size() && chars[4] == '-' && chars[7] == '-' && j + 2 < text.size() &&
           text[j] == ' ' && text[j + 1] >= '0' && text[j + 1] <= '9' && value_end(text[j + 2]);
  };
  while (i < text.size()) {
    const char c = text[i];
    const auto byte = static_cast<unsigned char>(c);
    if ((byte < 0x20 && c != '\t' && c != '\n' && c != '\r') || byte == 0x7F) {
      fail(fmt::format("a control character (code {}) in the file", byte));
    }
    std::size_t take = 1;
    const bool blank = c == ' ' || c == '\t' || c == '\r';
    if (byte >= 0x80) {
      if (state != State::normal && state != State::comment) {
        fail("a non-ASCII character in a string (scenes are ASCII but for their comments)");
      }
      if (state == State::comment) screened[i] = ' ';  // what a comment says does not matter
    }
    if (state == State::normal && !blank) {
      // What may come next, where the TOML library assumes rather than checks (toml++ 3.3
      // asserts on "[ = 1", "x = [}", "{ = 1}" and the like instead of reporting them).
      if (expect == Expect::value && (c == '\n' || c == '#')) fail("a value is missing after '='");
      if (expect != Expect::nothing && c != '\n' && c != '#') {
        const bool ok = expect == Expect::key          ? key_start(c)
                        : expect == Expect::key_or_end ? key_start(c) || c == '}'
                        : expect == Expect::element
                            ? std::string_view("},=#").find(c) == std::string_view::npos
                            : std::string_view("}],=").find(c) == std::string_view::npos;
        if (!ok) {
          fail(expect == Expect::key || expect == Expect::key_or_end ? "a key is missing"
                                                                     : "a value is missing");
        }
        expect = Expect::nothing;
      }
      const bool starts_value =
          i == 0 || value_end(text[i - 1]) || text[i - 1] == '=' || text[i - 1] == '[';
      if (c >= '0' && c <= '9' && starts_value && lone_time_digit(i)) {
        fail("a date followed by a lone digit is not a value");
      }
    }
    switch (state) {
      case State::normal:
        if (c == '#') {
          state = State::comment;
        } else if (starts(R"(""")")) {
          state = State::multi_basic;
          take = 3;
        } else if (starts("'''")) {
          state = State::multi_literal;
          take = 3;
        } else if (c == '"') {
          state = State::basic;
        } else if (c == '\'') {
          state = State::literal;
        } else if (byte >= 0x80) {
          fail("a non-ASCII character outside a string or comment");
        } else if (c == '[' && open.empty() && line_start && !in_header) {
          std::size_t j = i + 1;
          if (j < text.size() && text[j] == '[') take = 2, ++j;
          while (j < text.size() && (text[j] == ' ' || text[j] == '\t')) ++j;
          if (j >= text.size() || !key_start(text[j])) fail("a [section] header needs a name");
          in_header = true;
        } else if (c == ']' && in_header) {
          in_header = false;
          if (starts("]]")) take = 2;
        } else if (c == '=' && open.empty()) {
          expect = Expect::value;
        } else if (c == '=' && open.back() == '{') {
          expect = Expect::value;
        } else if (c == '[') {
          open.push_back('[');
          expect = Expect::element;
        } else if (c == '{') {
          open.push_back('{');
          expect = Expect::key_or_end;
        } else if (c == ',' && !open.empty()) {
          expect = open.back() == '[' ? Expect::element : Expect::key;
        } else if ((c == ']' || c == '}') && !open.empty()) {
          open.pop_back();
        }
        if (c == '\n') {
          line_start = true;
          in_header = false;
        } else if (!blank) {
          line_start = false;
        }
        break;
      case State::comment:
        if (c == '\n') {
          state = State::normal;
          line_start = true;
          in_header = false;
        }
        break;
      case State::basic:
        if (c == '\\') take = 2;
        if (c == '"' || c == '\n') state = State::normal;
        break;
      case State::literal:
        if (c == '\'' || c == '\n') state = State::normal;
        break;
      case State::multi_basic:
        if (c == '\\') {
          take = 2;
        } else if (starts(R"(""")")) {
          state = State::normal;
          take = 3;
        }
        break;
      case State::multi_literal:
        if (starts("'''")) {
          state = State::normal;
          take = 3;
        }
        break;
    }
    for (std::size_t k = 0; k < take && i < text.size(); ++k, ++i) {
      if (text[i] == '\n') {
        ++line;
        column = 1;
      } else {
        ++column;
      }
    }
  }
  if (expect == Expect::value) fail("a value is missing after '='");
  return screened;
}

const std::vector<std::string>& scene_sections() {
  static const std::vector<std::string> sections{
      "structure", "method", "run",   "analysis",     "sweep",
      "map",       "orbit",  "bench", "continuation", "output", "basin"};
  return sections;
}

Scene parse_scene(std::string_view text, const std::string& name,
                  const std::vector<std::string>& overrides) {
  Scene scene;
  scene.name = name;
  collect(parse_toml(text, name), name, false, &scene);
  // Tables iterate by key; the flags follow the file's order instead.
  std::stable_sort(
      scene.settings.begin(), scene.settings.end(),
      [](const SceneSetting& a, const SceneSetting& b) { return a.position < b.position; });
  for (const std::string& o : overrides) {
    const std::string at = fmt::format("--set {}", o);
    const std::size_t eq = o.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw InputError(fmt::format("{}: expected key=value, e.g. structure.theta=1.3", at));
    }
    const std::string key = o.substr(0, eq);
    const std::string value = o.substr(eq + 1);
    const std::size_t dot = key.find('.');
    // "section.key = value" under its section, or the top-level "job = value".
    const std::string snippet =
        dot == std::string::npos
            ? fmt::format("{} = ", key)
            : fmt::format("[{}]\n{} = ", key.substr(0, dot), key.substr(dot + 1));
    if (dot != std::string::npos &&
        (!valid_key(key.substr(0, dot)) || !valid_key(key.substr(dot + 1)))) {
      throw InputError(fmt::format("{}: '{}' is not a key: section.key, lowercase", at, key));
    }
    if (dot == std::string::npos && key != "job") {
      throw InputError(fmt::format(
          "{}: '{}' needs its section, e.g. structure.{} (sections: {})", at, key, key,
          fmt::join(scene_sections(), ", ")));
    }
    toml::table doc;
    try {
      doc = toml::parse(fmt::format("{}{}", snippet, value), at);
    } catch (const toml::parse_error&) {
      // Not a TOML value: take it as text ("--set method.name=pim").
      std::string quoted = "\"";
      for (char c : value) {
        if (c == '"' || c == '\\') quoted += '\\';
        if (static_cast<unsigned char>(c) < 0x20) {
          throw InputError(fmt::format("{}: control characters are not allowed in a value", at));
        }
        quoted += c;
      }
      doc = parse_toml(fmt::format("{}{}\"", snippet, quoted), at);
    }
    collect(doc, at, true, &scene);
  }
  return scene;
}

Scene load_scene(const std::string& path, const std::vector<std::string>& overrides) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("--scene {}: cannot read the file", path));
  std::ostringstream text;
  text << in.rdbuf();
  return parse_scene(text.str(), path, overrides);
}

std::vector<std::string> scene_arguments(const Scene& scene) {
  std::vector<std::string> args;
  for (const SceneSetting& s : scene.settings) {
    if (s.kind == SceneSetting::Kind::boolean && !s.switched_on) continue;
    args.push_back(s.flag);
    args.insert(args.end(), s.values.begin(), s.values.end());
  }
  if (scene.explicit_structure) {
    args.push_back("--structure-scene");
    args.push_back(scene.name);
  }
  return args;
}

}  // namespace pwl::app
