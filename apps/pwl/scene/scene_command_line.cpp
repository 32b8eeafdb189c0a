#include "scene/scene_command_line.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "pwl/errors.hpp"

namespace pwl::app {
namespace {

// The flag a command-line token sets ("--tol=1e-8" sets "--tol"), or "" for a value.
std::string flag_of_token(const std::string& token) {
  if (token.size() < 3 || token.compare(0, 2, "--") != 0) return "";
  return token.substr(0, token.find('='));
}

const char* kind_name(SceneSetting::Kind kind) {
  switch (kind) {
    case SceneSetting::Kind::boolean:
      return "true or false";
    case SceneSetting::Kind::integer:
      return "an integer";
    case SceneSetting::Kind::real:
      return "a number";
    case SceneSetting::Kind::text:
      return "text";
    case SceneSetting::Kind::list:
      return "a list";
  }
  return "a value";
}

// Whether the option takes this kind of value; else throws naming the scene key.
void check_setting(const SceneSetting& s, const CLI::App& job) {
  const CLI::Option* option = job.get_option_no_throw(s.flag);
  if (option == nullptr || option->get_group().empty()) {
    std::vector<std::string> known;
    for (const CLI::Option* o : job.get_options()) {
      const std::string name = o->get_name(false, true);
      if (!o->get_group().empty() && name.rfind("--", 0) == 0 && name != "--help" &&
          name != "--scene" && name != "--set") {
        std::string key = name.substr(2);
        std::replace(key.begin(), key.end(), '-', '_');
        if (key == "n") key = "masses";     // structure.masses
        if (key == "method") key = "name";  // method.name
        known.push_back(key);
      }
    }
    throw InputError(fmt::format("{}: {}: pwl {} has no setting {} (its settings: {})", s.where,
                                 s.key, job.get_name(), s.flag, fmt::join(known, ", ")));
  }
  const bool is_switch = option->get_expected_max() == 0;  // a flag expects no value
  const bool many = option->get_items_expected_max() > 1;
  const std::string type = option->get_type_name();
  std::string expected;
  if (is_switch) {
    if (s.kind != SceneSetting::Kind::boolean) expected = "true or false";
  } else if (s.kind == SceneSetting::Kind::boolean) {
    expected = "a value, not true/false";
  } else if (s.kind == SceneSetting::Kind::list && !many) {
    expected = "one value, not a list";
  } else if (type.find("INT") != std::string::npos || type.find("FLOAT") != std::string::npos) {
    const bool integral = type.find("INT") != std::string::npos;
    for (const std::string& v : s.values) {
      const bool number = !v.empty() && v.find_first_not_of("+-0123456789.eE") == std::string::npos;
      const bool whole = v.find_first_of(".eE") == std::string::npos;
      if (!number || (integral && !whole)) {
        expected = integral ? "an integer" : "a number";
        break;
      }
    }
  }
  if (!expected.empty()) {
    throw InputError(
        fmt::format("{}: {}: expected {}, got {}", s.where, s.key, expected, kind_name(s.kind)));
  }
}

std::vector<std::string> job_words(const std::string& job) {
  std::vector<std::string> words;
  std::size_t from = 0;
  while (from < job.size()) {
    const std::size_t end = std::min(job.find(' ', from), job.size());
    if (end > from) words.push_back(job.substr(from, end - from));
    from = end + 1;
  }
  return words;
}

// The subcommand that runs `job` ("simulate", "bench chain"), or nullptr: a job is a subcommand
// without subcommands of its own, and neither `run` nor `reproduce` (they run scenes).
const CLI::App* find_job(const CLI::App& app, const std::string& job) {
  const CLI::App* at = &app;
  for (const std::string& word : job_words(job)) {
    const CLI::App* next = nullptr;
    for (const CLI::App* sub : at->get_subcommands({})) {
      if (sub->get_name() == word) next = sub;
    }
    if (next == nullptr) return nullptr;
    at = next;
  }
  if (at == &app || !at->get_subcommands({}).empty()) return nullptr;
  if (at->get_name() == "run" || at->get_name() == "reproduce") return nullptr;
  return at;
}

// Consumed by expand_scenes before parsing; declared for --help.
void add_scene_options_to(CLI::App& job) {
  static std::string unused_path;
  static std::vector<std::string> unused_overrides;
  job.add_option("--scene", unused_path,
                 "Take the settings from this scene file (TOML); typed flags win")
      ->group("Scene");
  job.add_option("--set", unused_overrides,
                 "Override one scene setting: key=value, e.g. structure.theta=1.3")
      ->group("Scene");
}

}  // namespace

std::vector<std::string> job_names(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::App* sub : app.get_subcommands({})) {
    const std::vector<const CLI::App*> leaves = sub->get_subcommands({});
    if (leaves.empty()) {
      if (find_job(app, sub->get_name()) != nullptr) names.push_back(sub->get_name());
    } else {
      for (const CLI::App* leaf : leaves) names.push_back(sub->get_name() + " " + leaf->get_name());
    }
  }
  return names;
}

ExpandedCommandLine expand_scenes(const std::vector<std::string>& args, const CLI::App& app) {
  ExpandedCommandLine out;
  if (args.empty()) return out;
  std::string job;
  std::string path;
  std::vector<std::string> overrides;
  std::vector<std::string> rest;  // what the user typed, without the scene's own flags
  std::size_t i = 1;
  if (args[0] == "bench" && args.size() > 1 && args[1].rfind("-", 0) != 0) {
    job = "bench " + args[1];  // a benchmark is a job of its own: "bench chain"
    i = 2;
  } else if (args[0] == "run") {
    if (args.size() < 2 || args[1].rfind("-", 0) == 0) {
      out.args = args;  // `pwl run --help` and the like: the parser explains
      return out;
    }
    path = args[1];
    i = 2;
  } else {
    job = args[0];
  }
  for (; i < args.size(); ++i) {
    const std::string& a = args[i];
    const auto value_of = [&](const std::string& flag) -> std::string {
      if (a.size() > flag.size() && a[flag.size()] == '=') return a.substr(flag.size() + 1);
      if (i + 1 >= args.size()) throw InputError(fmt::format("{} needs a value", flag));
      return args[++i];
    };
    if (a == "--scene" || a.rfind("--scene=", 0) == 0) {
      if (!path.empty())
        throw InputError(fmt::format("--scene {}: only one scene per run", value_of("--scene")));
      path = value_of("--scene");
    } else if (a == "--set" || a.rfind("--set=", 0) == 0) {
      overrides.push_back(value_of("--set"));
    } else {
      rest.push_back(a);
    }
  }
  if (path.empty()) {
    if (!overrides.empty()) throw InputError("--set needs a scene (--scene FILE)");
    out.args = args;
    return out;
  }
  const Scene scene = load_scene(path, overrides);
  if (job.empty()) {
    job = scene.job;
    if (job.empty())
      throw InputError(fmt::format(
          "{}: job: the scene does not say which job it is (job = \"simulate\", ...)", path));
  }
  const CLI::App* sub = find_job(app, job);
  if (sub == nullptr) {
    throw InputError(fmt::format("{}: job = \"{}\": not a job of pwl (expected {})", path, job,
                                 fmt::join(job_names(app), ", ")));
  }
  std::vector<std::string> typed;
  for (const std::string& a : rest) {
    const std::string f = flag_of_token(a);
    if (!f.empty()) typed.push_back(f);
  }
  for (const std::string& word : job_words(job)) out.args.push_back(word);
  Scene kept = scene;
  kept.settings.clear();
  for (const SceneSetting& s : scene.settings) {
    check_setting(s, *sub);
    if (std::find(typed.begin(), typed.end(), s.flag) == typed.end()) kept.settings.push_back(s);
  }
  if (scene.explicit_structure && sub->get_option_no_throw("--structure-scene") == nullptr) {
    throw InputError(fmt::format(
        "{}: structure: pwl {} takes only the chain's parameters, not an explicit structure", path,
        job));
  }
  const std::vector<std::string> scene_args = scene_arguments(kept);
  out.args.insert(out.args.end(), scene_args.begin(), scene_args.end());
  out.args.insert(out.args.end(), rest.begin(), rest.end());
  out.settings = kept.settings;
  return out;
}

namespace {

// Whether `word` occurs in `text` on its own (not inside a longer name like "skip-periods").
bool names(const std::string& text, const std::string& word) {
  const auto part_of_name = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_';
  };
  for (std::size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) {
    const std::size_t end = at + word.size();
    if ((at == 0 || !part_of_name(text[at - 1])) &&
        (end == text.size() || !part_of_name(text[end])))
      return true;
  }
  return false;
}

}  // namespace

std::string locate_in_scene(const std::string& message, const ExpandedCommandLine& line) {
  // The message names the flag ("--record 9: ...") or the setting ("theta = -1.1 must be ...").
  for (const SceneSetting& s : line.settings) {
    const std::string name = s.flag.substr(2);
    std::string underscored = name;
    std::replace(underscored.begin(), underscored.end(), '-', '_');
    if (names(message, s.flag) || names(message, name) || names(message, underscored))
      return fmt::format("{}: {}: {}", s.where, s.key, message);
  }
  return message;
}

void add_scene_options(CLI::App& app) {
  for (const std::string& name : job_names(app)) {
    CLI::App* job = &app;
    for (const std::string& word : job_words(name)) job = job->get_subcommand(word);
    add_scene_options_to(*job);
  }
}

void add_run_command(CLI::App& app) {
  static std::string unused_path;
  static std::vector<std::string> unused_overrides;
  CLI::App* c =
      app.add_subcommand("run",
                         "Run the job a scene file describes (simulate, analyze, sweep, map, basin,\n"
                         "orbit, continue or a benchmark)\n"
                         "Example: pwl run apps/scenes/paper_fig4b.toml --set structure.theta=1.1");
  c->add_option("scene", unused_path, "The scene file")->required();
  c->add_option("--set", unused_overrides, "Override one scene setting: key=value");
  c->callback([] { throw InputError("pwl run: the scene could not be expanded"); });
}

}  // namespace pwl::app
