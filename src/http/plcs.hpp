#pragma once
// `GET /api/v1/plcs` and `GET /api/v1/plcs/{plc}`: the PLCs of the listener and their state.

#include <chrono>
#include <string>

#include "http/api.hpp"

namespace plcemu::http {

/// A wall-clock time as ISO 8601 UTC with milliseconds ("2026-11-28T13:05:00.123Z"); "" for none.
std::string wall_time(std::chrono::system_clock::time_point t);

/// A client of a PLC as the API lists it.
Json client_json(const listener::ClientFigures& c);

/// One PLC as the API describes it.
Json describe(const listener::Seat& plc);

/// `GET /api/v1/plcs`.
Response plcs(const Call& call);

}  // namespace plcemu::http
