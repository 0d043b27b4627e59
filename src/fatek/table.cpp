// The FATEK command table: one row and one handler per code.

#include "command.hpp"

namespace plcemu::fatek {

namespace {

constexpr CommandTable make_table() {
    CommandTable t{};
    t[0x40] = {&handlers::gist_status};
    t[0x41] = {&handlers::run_stop};
    t[0x42] = {&handlers::discrete_control};
    t[0x43] = {&handlers::read_disable_flags};
    t[0x44] = {&handlers::read_discretes};
    t[0x45] = {&handlers::write_discretes};
    t[0x46] = {&handlers::read_registers};
    t[0x47] = {&handlers::write_registers};
    t[0x48] = {&handlers::mixed_read};
    t[0x49] = {&handlers::mixed_write};
    t[0x4E] = {&handlers::loop_back, false};
    t[0x53] = {&handlers::detailed_status};
    return t;
}

constexpr CommandTable kCommands = make_table();

}  // namespace

const CommandTable& commands() noexcept { return kCommands; }

}  // namespace plcemu::fatek
