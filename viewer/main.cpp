// SPDX-License-Identifier: Apache-2.0
// viewer: the graphics process (paper §6.1, docs/architecture.md §1). Shows a running world live, read-only, or replays
// a finished trial, as a 3-D page served on loopback.

#include "common/runtime/cli.h"
#include "viewer/viewer_node.h"

int main(int argc, char** argv) {
  using namespace impetus;
  view::ViewerOptions options;
  std::string web_dir;
  CLI::App app{"viewer: watch an Impetus world in a browser. Attaches read-only to a running world (--shm on its host, or "
               "--link dds from any host) or replays "
               "a finished trial (--replay), and serves a 3-D page at --listen."};
  add_shm_flag(app, options.shm);
  add_link_flags(app, options.link);
  app.add_option("--replay", options.replay_dir, "replay a finished trial: its folder (scripts/run.sh --out DIR)")
      ->check(CLI::ExistingDirectory);
  app.add_option("--listen", options.listen, "HOST:PORT to serve the page on (port 0: any free port)")
      ->capture_default_str();
  app.add_flag("--allow-remote", options.allow_remote, "allow a --listen address other than loopback");
  app.add_option("--allow-host", options.allow_hosts,
                 "with --allow-remote: a DNS name the page may be opened by, besides IP addresses and this machine's "
                 "name (any other Host is refused: DNS rebinding)")
      ->needs("--allow-remote");
  app.add_flag("--touch", options.touch,
               "let a page steer the web hand (haptic_controller --device web on the same --shm): the page opened "
               "from the address printed with the run's token takes it, one page at a time");
  app.add_flag("--allow-remote-touch", options.allow_remote_touch,
               "with --touch and --allow-remote: accept input from pages on other machines")
      ->needs("--touch");
  app.add_option("--meshes-from", options.meshes_from,
                 "live: the world's scene file; its meshes are read so the page draws their triangles (else a mesh "
                 "is drawn as a ball that holds it), and its tool, drawn in the hand that holds it")
      ->check(CLI::ExistingFile);
  app.add_option("--web", web_dir, "folder with the page (default: the installed or source viewer/web)")
      ->check(CLI::ExistingDirectory);
  app.add_option("--duration", options.duration_s, "seconds to serve (default: until stopped)")
      ->check(positive_number(kMaxFlagSeconds));
  if (const std::optional<int> status = parse_flags(app, "viewer", argc, argv)) return *status;
  options.web_dir = web_dir;
  return run_node("viewer", [&] {
    view::ViewerNode node(options, argv[0]);
    return node.run();
  });
}
