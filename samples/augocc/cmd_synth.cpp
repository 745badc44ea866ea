// augocc synth: placeholder until the SceneSynthesizer lands.

#include "cli_common.hpp"

namespace augocc_cli {

void registerSynth(CLI::App& app, Globals&)
{
    CLI::App* sub = app.add_subcommand("synth", "write a synthesized data set");
    sub->callback([]() { throw UsageError("synth: not implemented yet"); });
}

} // namespace augocc_cli
