#pragma once
// `GET/PUT/DELETE /api/v1/plcs/{plc}/comm-faults`: the PLC's communication faults
// (docs/communication-faults.md), with the names of the config's `faults:` section. PUT replaces
// the whole set (a key left out is off), DELETE switches every fault off.

#include "http/api.hpp"

namespace plcemu::http {

/// `GET/PUT/DELETE /api/v1/plcs/{plc}/comm-faults`.
Response comm_faults(const Call& call, const listener::Seat& plc);

}  // namespace plcemu::http
