#pragma once
// From a request to its handler: the console's pages, its static files, the REST API under
// /api/v1, /healthz and /metrics (docs/console.md has the table).

#include <optional>

#include "http/api.hpp"
#include "http/events.hpp"

namespace plcemu::http {

/// What a request gets: a response, or (an events request) a subscription whose stream the
/// session then carries.
struct Routed {
    Response response;
    std::optional<Subscription> stream;
};

/// Answers one request.
Routed route(const Request& request, listener::UnitTable& units);

}  // namespace plcemu::http
