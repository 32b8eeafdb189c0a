// libFuzzer target for the scene parser: any bytes either parse or are refused with InputError;
// nothing else may escape, crash, hang or trip the sanitizers. Built and run briefly by
// tests/scene_fuzz.cmake (clang only), seeded with the shipped scenes.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "pwl/errors.hpp"
#include "scene/scene.hpp"
#include "scene/scene_structure.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  // The last line, when it looks like key=value, is also tried as an override.
  std::vector<std::string> overrides;
  const std::size_t newline = text.rfind('\n');
  if (newline != std::string_view::npos && text.find('=', newline) != std::string_view::npos) {
    overrides.emplace_back(text.substr(newline + 1));
  }
  try {
    const pwl::app::Scene scene = pwl::app::parse_scene(text, "fuzz.toml", overrides);
    (void)pwl::app::scene_arguments(scene);
    if (scene.explicit_structure) (void)pwl::app::parse_scene_structure(text, "fuzz.toml");
  } catch (const pwl::InputError&) {
    // refused with a message: the expected outcome for bad input
  }
  return 0;
}
