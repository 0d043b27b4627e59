#pragma once
// `GET/PUT /api/v1/plcs/{plc}/simulator`: time control (freeze, scale, step), the plant's
// channels and their process faults — what the simulator-control unit offers over Modbus
// (docs/simulator-and-plant.md), by name.

#include "http/api.hpp"

namespace plcemu::http {

/// `GET/PUT /api/v1/plcs/{plc}/simulator`.
Response simulator(const Call& call, const listener::Seat& plc);

}  // namespace plcemu::http
