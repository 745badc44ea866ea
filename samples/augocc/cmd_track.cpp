// augocc track: placeholder until its stage lands (exit 2, "not implemented yet").

#include "cli_common.hpp"

namespace augocc_cli {

void registerTrack(CLI::App& app, Globals&)
{
    CLI::App* sub = app.add_subcommand("track", "(not implemented yet)");
    sub->allow_extras();
    sub->callback([]() { throw UsageError("track: not implemented yet"); });
}

} // namespace augocc_cli
