#pragma once
// `GET /healthz` and `GET /metrics` (Prometheus' text format, version 0.0.4).

#include "http/api.hpp"

namespace plcemu::http {

/// `GET /healthz`: 200 while every PLC's scan keeps its schedule, 503 otherwise.
Response health(const Call& call);

/// `GET /metrics`.
Response metrics(const Call& call);

}  // namespace plcemu::http
