// augocc clone: placeholder until its stage lands (exit 2, "not implemented yet").

#include "cli_common.hpp"

namespace augocc_cli {

void registerClone(CLI::App& app, Globals&)
{
    CLI::App* sub = app.add_subcommand("clone", "(not implemented yet)");
    sub->allow_extras();
    sub->callback([]() { throw UsageError("clone: not implemented yet"); });
}

} // namespace augocc_cli
