// Scene files: text to flags, overrides, explicit structures, and messages that name the file,
// line and key.
#include "scene/scene.hpp"

#include <catch2/catch.hpp>
#include <toml++/toml.h>
#include <filesystem>
#include <string>
#include <vector>

#include "pwl/errors.hpp"
#include "scene/scene_structure.hpp"

using namespace pwl;
using namespace pwl::app;

namespace {

// The message of the InputError `f` throws ("" if it does not throw).
template <class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

const char* kFigure4b = R"(job = "analyze"
[structure]
figure = "4b"
loads = [1, -1, 1.5, -1, 1]
[method]
name = "dopri5"
tol = 1e-8
locate_kinks = true
[run]
periods = 400
[analysis]
transient = 250
[output]
out = "out/x"
quiet = false
)";

}  // namespace

TEST_CASE("scene: settings become the job's flags in file order", "[scene]") {
  const Scene s = parse_scene(kFigure4b, "a.toml");
  CHECK(s.job == "analyze");
  CHECK_FALSE(s.explicit_structure);
  const std::vector<std::string> expected{"--figure",
                                          "4b",
                                          "--loads",
                                          "1",
                                          "-1",
                                          "1.5",
                                          "-1",
                                          "1",
                                          "--method",
                                          "dopri5",
                                          "--tol",
                                          "1e-08",
                                          "--locate-kinks",
                                          "--periods",
                                          "400",
                                          "--transient",
                                          "250",
                                          "--out",
                                          "out/x"};
  CHECK(scene_arguments(s) == expected);
  REQUIRE(s.settings.size() == 9);  // quiet = false is kept, switched off
  CHECK(s.settings[1].where == "a.toml:4:9");
  CHECK(s.settings[1].kind == SceneSetting::Kind::list);
  CHECK(s.settings[4].kind == SceneSetting::Kind::boolean);
  CHECK_FALSE(s.settings[8].switched_on);
}

TEST_CASE("scene: masses and method.name are renamed; overrides replace and add", "[scene]") {
  const Scene s =
      parse_scene("job = \"simulate\"\n[structure]\nmasses = 8\ntheta = 1.0\n", "b.toml",
                  {"structure.theta=1.3", "method.name=pim-banded", "job=analyze",
                   "run.record=[1, 8]", "output.quiet=true"});
  CHECK(s.job == "analyze");
  const std::vector<std::string> expected{"--n",        "8",        "--theta", "1.3", "--method",
                                          "pim-banded", "--record", "1",       "8",   "--quiet"};
  CHECK(scene_arguments(s) == expected);
  CHECK(s.settings[1].where == "--set structure.theta=1.3");
}

TEST_CASE("scene: bad scenes are refused with file, line and key", "[scene]") {
  CHECK(message_of([] {
          parse_scene("job = \"simulate\"\n[run\nperiods = 5\n", "c.toml");
        }).find("c.toml:2:") == 0);
  CHECK(message_of([] {
          parse_scene("[solver]\nstep = 1\n", "c.toml");
        }).find("c.toml:1:2: 'solver': unknown section") == 0);
  CHECK(message_of([] { parse_scene("periods = 5\n", "c.toml"); }).find("unknown top-level key") !=
        std::string::npos);
  CHECK(message_of([] {
          parse_scene("[run]\nperiods = 5\n[run.inner]\nx = 1\n", "c.toml");
        }).find("run.inner: sections do not nest") != std::string::npos);
  CHECK(message_of([] {
          parse_scene("[structure]\nloads = [1, \"a\"]\n", "c.toml");
        }).find("c.toml:2:9: structure.loads: the list mixes numbers and text") == 0);
  CHECK(message_of([] {
          parse_scene("[structure]\nloads = [[1], [2]]\n", "c.toml");
        }).find("element 1 of the list is a list") != std::string::npos);
  CHECK(message_of([] {
          parse_scene("[structure]\ntheta = nan\n", "c.toml");
        }).find("c.toml:2:9: structure.theta: expected a finite number") == 0);
  CHECK(message_of([] { parse_scene("[structure]\nloads = []\n", "c.toml"); }).find("empty list") !=
        std::string::npos);
  CHECK(message_of([] {
          parse_scene("[run]\n\"Periods\" = 5\n", "c.toml");
        }).find("'run.Periods': a key is lowercase") != std::string::npos);
  CHECK(message_of([] { parse_scene("job = 3\n", "c.toml"); }).find("job: expected text") !=
        std::string::npos);
  CHECK(message_of([] {
          parse_scene("", "c.toml", {"theta=1"});
        }).find("needs its section, e.g. structure.theta") != std::string::npos);
  CHECK(message_of([] { parse_scene("", "c.toml", {"=1"}); }).find("expected key=value") !=
        std::string::npos);
  CHECK(message_of([] {
          parse_scene("[structure]\nmass = [[1.0]]\n", "c.toml", {"structure.mass=[[2.0]]"});
        }).find("cannot be overridden") != std::string::npos);
  CHECK(message_of([] { load_scene("/nonexistent/scene.toml"); }).find("cannot read") !=
        std::string::npos);
  // Non-ASCII text is fine in comments, refused elsewhere (the fuzzer's first find).
  CHECK_NOTHROW(parse_scene("# θ sweep\n[output]\nout = \"x\" # α\n", "c.toml"));
  CHECK(message_of([] {
          parse_scene("[output]\nout = \"θ\"\n", "c.toml");
        }).find("c.toml:2:8: a non-ASCII character in a string") == 0);
  CHECK(message_of([] {
          parse_scene("[run]\nperiods = 5 θ\n", "c.toml");
        }).find("c.toml:2:13: a non-ASCII character outside a string or comment") == 0);
  CHECK(message_of([] {
          parse_scene("\xEF\xBB\xBF \xCE\xB8 = 1\n", "c.toml");
        }).find("c.toml:1:2: a non-ASCII") == 0);
  CHECK(message_of([] {
          parse_scene(std::string("[r\0un]\n", 7), "c.toml");
        }).find("c.toml:1:3: a control character (code 0)") == 0);
  // Malformed headers that toml++ 3.3 asserts on instead of reporting.
  for (const char* header : {"[ = 2\n", "[&\n", "[[[1]]]\n", "[[=\n", "x = 1\n  [{ a = 1 }]\n"}) {
    CHECK(message_of([&] { parse_scene(header, "c.toml"); }).find("header needs a name") !=
          std::string::npos);
  }
  for (const char* value : {"m = [}\n", "m = [1, }]\n", "m = [,]\n", "m = { = 1 }\n",
                            "m = {a = 1, }\n", "m =\n", "m = # c\n", "m = ]\n", "m = "}) {
    CHECK(message_of([&] { parse_scene(value, "c.toml"); }).find("is missing") !=
          std::string::npos);
  }
  // A date-like value, a space, one digit and the value's end: toml++ 3.3 asserts (the fuzzer's
  // find: oas=  10`0-1E-e" 0 = '''a). A date and time, a longer value and a digit at the end of
  // the text are left to the library.
  for (const char* value : {"m = 1979-05-27 1\n", "m = [1979-05-27 1]\n", "m = 1_979-05-27 1,\n",
                            "oas=  10`0-1E-e\" 0 = '''a\n"}) {
    CHECK(message_of([&] { parse_scene(value, "c.toml"); })
              .find("a date followed by a lone digit") != std::string::npos);
  }
  for (const char* value : {"m = 1979-05-27 12\n", "m = 1979-05-27 1", "m = 11979-05-27 1\n"}) {
    CHECK(message_of([&] { parse_scene(value, "c.toml"); })
              .find("a date followed by a lone digit") == std::string::npos);
  }
  // Arrays that start a line are values, not headers.
  CHECK(parse_scene("[structure]\nmass = [\n[1.0, 0.0],\n  [0.0, 1.0]]\n", "c.toml")
            .explicit_structure);
}

TEST_CASE("scene: an explicit structure", "[scene]") {
  const char* text = R"(job = "simulate"
[structure]
mass = [[2.0, 0.0], [0.0, 1.0]]
damping = [[0.1, 0.0], [0.0, 0.1]]
stiffness = [[2, -1], [-1, 1]]
spring = [{ mass = 2, stiffness = 4.0, gap = 0.2 },
          { mass = 1, other_mass = 2, direction = -1, stiffness = 1.0, gap = -0.1 }]
load = [{ mass = 2, amplitude = 1.5, omega = 1.2, phase = 0.5 }]
)";
  const Scene s = parse_scene(text, "d.toml");
  CHECK(s.explicit_structure);
  CHECK(scene_arguments(s) == std::vector<std::string>{"--structure-scene", "d.toml"});
  const GapStructure g = parse_scene_structure(text, "d.toml");
  REQUIRE(g.dofs() == 2);
  CHECK(Matrix(g.mass)(0, 0) == 2.0);
  CHECK(Matrix(g.stiffness)(0, 1) == -1.0);
  CHECK(Matrix(g.damping)(1, 1) == 0.1);
  REQUIRE(g.springs.size() == 2);
  CHECK(g.springs[0].dof == 1);
  CHECK(g.springs[0].other_dof == -1);
  CHECK(g.springs[0].direction == 1.0);
  CHECK(g.springs[1].dof == 0);
  CHECK(g.springs[1].other_dof == 1);
  CHECK(g.springs[1].direction == -1.0);
  CHECK(g.springs[1].gap == -0.1);
  REQUIRE(g.loads.size() == 1);
  CHECK(g.loads[0].dof == 1);
  CHECK(g.loads[0].amplitude == 1.5);
  CHECK(g.loads[0].phase == 0.5);
}

TEST_CASE("scene: bad explicit structures name the key", "[scene]") {
  const auto err = [](const std::string& body) {
    return message_of([&] { parse_scene_structure("[structure]\n" + body, "e.toml"); });
  };
  CHECK(err("damping = [[1.0]]\n").find("structure.mass: an explicit structure needs") !=
        std::string::npos);
  CHECK(err("mass = [[1.0, 0.0], [0.0]]\n")
            .find("e.toml:2:21: structure.mass: row 2 must be a list of 2") == 0);
  CHECK(err("mass = [[1.0]]\nstiffness = [[1, 0], [0, 1]]\n")
            .find("structure.stiffness is 2x2; the mass matrix is 1x1") != std::string::npos);
  CHECK(err("mass = [[1.0]]\nspring = [{ mass = 2, stiffness = 1 }]\n")
            .find("structure.spring[1].mass = 2: masses are numbered 1..1") != std::string::npos);
  CHECK(err("mass = [[1.0]]\nspring = [{ mass = 1 }]\n").find("'stiffness' is required") !=
        std::string::npos);
  CHECK(err("mass = [[1.0]]\nspring = [{ mass = 1, stiffness = 1, gapp = 0 }]\n")
            .find("structure.spring[1].gapp: unknown") != std::string::npos);
  CHECK(err("mass = [[1.0]]\nload = [{ mass = 1, amplitude = \"big\", omega = 1 }]\n")
            .find("structure.load[1].amplitude: expected a finite number") != std::string::npos);
  CHECK(err("mass = [[-1.0]]\n").find("e.toml: structure: ") == 0);  // GapStructure's own check
}

TEST_CASE("scene: every shipped scene parses", "[scene]") {
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(PWL_SCENES_DIR)) {
    if (entry.path().extension() != ".toml") continue;
    ++count;
    const Scene s = load_scene(entry.path().string());
    CHECK(!s.job.empty());
    if (s.explicit_structure) {
      // As many degrees of freedom and gap springs as the file's mass rows and spring entries
      // (read here with toml++ on its own).
      const toml::table file = toml::parse_file(entry.path().string());
      const GapStructure structure = read_scene_structure(entry.path().string());
      REQUIRE(file["structure"]["mass"].as_array() != nullptr);
      REQUIRE(file["structure"]["spring"].as_array() != nullptr);
      CHECK(structure.dofs() ==
            static_cast<pwl::Index>(file["structure"]["mass"].as_array()->size()));
      CHECK(structure.spring_count() ==
            static_cast<pwl::Index>(file["structure"]["spring"].as_array()->size()));
    }
  }
  CHECK(count >= 6);
}
