// SPDX-License-Identifier: Apache-2.0
// world_manager: the rigid-body world at the world rate (docs/architecture.md §1.1). Parses the flags, creates the
// world link and runs a WorldNode on it; writes the world half of summary.json at exit.

#include "common/link/dds/open_world_link.h"
#include "common/runtime/cli.h"
#include "world_manager/defaults.h"
#include "world_manager/engine/engine_registry.h"
#include "world_manager/world_node.h"

#include <memory>
#include <string>

namespace {
// A phase is less than one world period in haptic ticks, and the longest period is the fastest haptic rate over the
// slowest world rate; WorldNode checks it against the actual period.
constexpr std::uint64_t kMaxPhaseTicks =
    static_cast<std::uint64_t>(impetus::limits::kMaxHapticRate_Hz / impetus::limits::kMinWorldRate_Hz);
}  // namespace

int main(int argc, char** argv) {
  using namespace impetus;
  WorldNodeOptions options;
  std::string summary_path;
  std::string shm = "impetus";
  LinkOptions link_options;
  CLI::App app{"world_manager: the physics world of Impetus. Steps a scene at the world rate, applies the haptic "
               "controller's impulses and publishes the planes near the finger."};
  app.add_option("--scene", options.scene_path, "scene file (JSON, see scenes/)")->required()->check(CLI::ExistingFile);
  app.add_option("--rate", options.rate_hz, "world rate in Hz, 0.1 to 10000 (default: the scene's world_rate_hz)")
      ->check(number_in(limits::kMinWorldRate_Hz, limits::kMaxWorldRate_Hz));
  app.add_option("--substeps", options.substeps,
                 "engine steps per world period (default: the scene's physics.substeps)")
      ->check(whole_number_in(1, limits::kMaxSubsteps));
  app.add_option("--engine", options.engine,
                 "the rigid-body engine, " + engine_names() + " (default: the scene's physics.engine)")
      ->check(CLI::Validator(
          [](std::string& name) {
            return find_engine(name) != nullptr ? std::string() : "must be " + engine_names() + ", not '" + name + "'";
          },
          "ENGINE"));
  app.add_option("--coupling", options.coupling, "impulse (paper §2.2), position (the previous method) or local")
      ->transform(enum_names(kCouplingNames));
  app.add_option("--passivity", options.passivity,
                 "on: the energy the couplings give a body never exceeds what the hands put in "
                 "(docs/latency.md); off: the paper's couplings as they are (default: off)")
      ->transform(enum_names(kOnOffNames));
  add_clock_flag(app, options.clock);
  app.add_option("--phase", options.phase_ticks, "lockstep: world step i happens at haptic tick i*n + PHASE")
      ->check(whole_number_in(0, kMaxPhaseTicks));
  app.add_option("--duration", options.duration_s, "seconds of world time to run (default: until stopped)")
      ->check(positive_number(kMaxFlagSeconds));
  add_output_flag(app, "--log", options.log_path, "CSV log of every dynamic object per step");
  add_output_flag(app, "--summary", summary_path, "JSON summary written at exit (objects, loop statistics)");
  add_shm_flag(app, shm);
  add_link_flags(app, link_options);
  app.add_option("--haptic-rate", options.haptic_rate_hz, "haptic rate the lockstep phase is counted in (1000)")
      ->check(number_in(limits::kMinHapticRate_Hz, limits::kMaxHapticRate_Hz));
  app.add_flag_callback(
      "--defaults",
      [] {
        std::printf("%s\n", defaults_document().dump(2).c_str());
        throw CLI::Success();  // printed: exit 0 before the required flags are checked
      },
      "print the couplings, engines, shapes and scene defaults as JSON, and exit");
  if (const std::optional<int> status = parse_flags(app, "world_manager", argc, argv)) return *status;

  return run_node("world_manager", [&] {
    prepare_engines();
    WorldNode node(options);
    // The world link by --link; the world-state view stays in shared memory on this host either way.
    const std::unique_ptr<WorldLinkServer> link = open_world_link_server(link_options, shm, node.link_info());
    node.connect(*link);
    // The world view: "<shm>.view" for viewers on this host (read-only), and over DDS too with --link dds.
    const std::unique_ptr<WorldViewPublisher> view = open_world_view_publisher(link_options, shm);
    node.connect_view(*view);
    const WorldLinkInfo info = node.link_info();
    std::fprintf(stderr, "world_manager: '%s', %zu objects, %.1f Hz, %s coupling, %s clock, link %s\n",
                 options.scene_path.c_str(), node.world().scene().objects.size(), info.world_rate_hz,
                 to_string(info.coupling), to_string(info.clock), link_name(*link).c_str());
    for (const std::string& warning : node.warnings()) {
      std::fprintf(stderr, "world_manager: warning: %s\n", warning.c_str());
    }
    const int status = node.run();
    nlohmann::json summary = node.summary();
    if (nlohmann::json dds = link_summary(*link, link_options); !dds.is_null()) summary["world"]["dds"] = dds;
    write_summary(summary_path, summary);
    std::fprintf(stderr, "world_manager: %llu steps, %.3f s simulated\n",
                 static_cast<unsigned long long>(node.world().steps_taken()), node.world().time_s());
    return status;
  });
}
