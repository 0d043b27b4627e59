#pragma once
// `GET /api/v1/plcs/{plc}/loops`: the control loops of the PLC's program (FBs TPCTL points, VB
// PID and TPID channels) with their values now — what the loops page's faceplates show. Their
// set points, parameters and switches are written through the devices endpoint.

#include "http/api.hpp"
#include "plcemu/engine/loop_history.hpp"
#include "plcemu/engine/loops.hpp"

namespace plcemu::http {

/// `GET /api/v1/plcs/{plc}/loops`. The PLC's loops are sampled for their trends from then on.
Response loops(const Call& call, const listener::Seat& plc);

/// `GET /api/v1/plcs/{plc}/loops/history`: each loop's samples of the last 10 simulated
/// minutes, one a simulated second, from when the loops were first asked for.
Response loop_history(const Call& call, const listener::Seat& plc);

}  // namespace plcemu::http
