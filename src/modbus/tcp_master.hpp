#pragma once
// Modbus TCP master on the event loop: one connection per endpoint, opened when a transaction
// needs it and kept for the next; MBAP framing with the slave side's codec. Nothing blocks: a
// slave that is down, silent, slow or sends garbage costs its own transaction's deadline and
// never more than one small buffer per endpoint; one that misbehaves transfer after transfer is
// reconnected less and less often, one that sends what nobody asked for is closed, and their
// log lines are rate-limited (docs/profile-vb.md, "Transports: `mbus:`").

#include <asio.hpp>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "master_transport.hpp"

namespace plcemu::modbus {

/// Where each station's requests go.
struct TcpMasterOptions {
    std::optional<asio::ip::tcp::endpoint> fallback;  ///< every station not routed
    /// Stations with an endpoint of their own.
    std::vector<std::pair<std::uint8_t, asio::ip::tcp::endpoint>> routes;
};

struct TcpMasterState;

/// The TCP master.
class TcpMaster final : public SharedStateTransport<TcpMasterState> {
public:
    TcpMaster(asio::io_context& io, TcpMasterOptions options);
    ~TcpMaster() override;
    TcpMaster(const TcpMaster&) = delete;
    TcpMaster& operator=(const TcpMaster&) = delete;
};

}  // namespace plcemu::modbus
