// airtwin: the command-line entry point. Exit status: 0 success, 2 usage error (bad or missing
// flag), 1 bad input or failed run; every failure prints exactly one line on stderr.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <string>

#include "app/commands.h"
#include "common/errors.h"

int main(int argc, char** argv) {
  CLI::App app{
      "airtwin: digital twin of remote airflow manipulation (jet-induced air field on a floor,\n"
      "object dynamics, MuJoCo twin, camera, CEM controller). Run 'airtwin <command> --help'."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "airtwin 0.1.0");
  airtwin::cli::add_field_command(app);
  airtwin::cli::add_aim_command(app);
  airtwin::cli::add_fitfield_command(app);
  airtwin::cli::add_maketable_command(app);
  airtwin::cli::add_hotwire_command(app);
  airtwin::cli::add_probe_command(app);
  airtwin::cli::add_identify_command(app);
  airtwin::cli::add_collect_command(app);
  airtwin::cli::add_calibrate_dynamics_command(app);
  airtwin::cli::add_run_command(app);
  airtwin::cli::add_view_command(app);
  airtwin::cli::add_scene_command(app);
  airtwin::cli::add_batch_command(app);
  airtwin::cli::add_batch_merge_command(app);
  airtwin::cli::add_render_command(app);
  airtwin::cli::add_calibrate_command(app);
  airtwin::cli::add_detect_command(app);
  airtwin::cli::add_trajectories_command(app);
  airtwin::cli::add_discrepancy_command(app);
  airtwin::cli::add_region_command(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::string where = "airtwin";
    for (const CLI::App* sub : app.get_subcommands()) where += " " + sub->get_name();
    std::string message = e.what();
    // A first word that is no command: name it and list the commands.
    if (app.get_subcommands().empty() && argc > 1 && argv[1][0] != '-') {
      message = std::string("unknown command '") + argv[1] + "'; commands:";
      for (const CLI::App* sub : app.get_subcommands({})) message += " " + sub->get_name();
    }
    std::fprintf(stderr, "%s: usage error: %s (see '%s --help')\n", where.c_str(), message.c_str(),
                 where.c_str());
    return 2;
  } catch (const airtwin::UsageError& e) {
    std::string where = "airtwin";
    for (const CLI::App* sub : app.get_subcommands()) where += " " + sub->get_name();
    std::fprintf(stderr, "%s: usage error: %s (see '%s --help')\n", where.c_str(), e.what(),
                 where.c_str());
    return 2;
  } catch (const airtwin::InputError& e) {
    std::fprintf(stderr, "airtwin: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "airtwin: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
