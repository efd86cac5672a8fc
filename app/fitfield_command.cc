// PLACEHOLDER (being implemented): airtwin fitfield
#include "app/commands.h"
namespace airtwin::cli {
void add_fitfield_command(CLI::App& app) { app.add_subcommand("fitfield", "(in progress)"); }
}  // namespace airtwin::cli
