#pragma once
// `GET /api/v1/plcs/{plc}/loops`: the control loops of the PLC's program (FBs TPCTL points, VB
// PID and TPID channels) with their values now — what the loops page's faceplates show. Their
// set points, parameters and switches are written through the devices endpoint.

#include "http/api.hpp"
#include "plcemu/engine/loops.hpp"

namespace plcemu::http {

/// The loops of the PLC's program, in program order.
engine::Loops loops_of(const listener::Seat& plc);

/// `GET /api/v1/plcs/{plc}/loops`.
Response loops(const Call& call, const listener::Seat& plc);

}  // namespace plcemu::http
