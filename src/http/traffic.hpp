#pragma once
// `GET /api/v1/plcs/{plc}/traffic`: the PLC's clients and the last requests they made,
// decoded (function, unit, devices, exception).

#include "http/api.hpp"

namespace plcemu::http {

/// `GET /api/v1/plcs/{plc}/traffic?count=N` (the last N requests, 1–256, default 100).
Response traffic(const Call& call, const listener::Seat& plc);

}  // namespace plcemu::http
