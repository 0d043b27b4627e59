#pragma once
// The engine's outbound link over a Modbus master port on the event loop: a master instruction's
// request becomes a PDU sent by the TCP or RTU master, and the reply, checked against the
// request, waits as a completion until the instruction polls at its next execution.

#include <asio.hpp>
#include <array>
#include <memory>
#include <optional>

#include "modbus/master_pdu.hpp"
#include "modbus/master_transport.hpp"
#include "plcemu/config/master.hpp"
#include "plcemu/engine/outbound.hpp"

namespace plcemu::daemon {

/// An outbound link over one master port.
class MasterLink final : public engine::OutboundLink {
public:
    explicit MasterLink(std::unique_ptr<modbus::MasterTransport> transport);
    ~MasterLink() override;
    MasterLink(const MasterLink&) = delete;
    MasterLink& operator=(const MasterLink&) = delete;

    bool submit(const engine::OutboundRequest& request) noexcept override;
    std::optional<engine::OutboundCompletion> poll() noexcept override;
    void abandon() noexcept override;

    /// Where requests go, as logged.
    std::string description() const { return transport_->description(); }

private:
    void on_done(modbus::MasterOutcome outcome, std::span<const std::uint8_t> pdu) noexcept;

    std::unique_ptr<modbus::MasterTransport> transport_;
    std::array<std::uint8_t, modbus::kMaxRequestPdu> request_{};
    std::size_t request_size_ = 0;
    bool busy_ = false;
    std::optional<engine::OutboundCompletion> result_;
};

/// Opens the master port `config` describes on `io`. RTU: opens the serial device; when it
/// cannot, throws std::system_error if `strict` (at start), else logs it and tries again at
/// every transfer (at a reload: the running PLC keeps its port and shows status 5 meanwhile).
std::unique_ptr<MasterLink> open_master_link(asio::io_context& io,
                                             const config::MasterConfig& config,
                                             bool strict = true);

}  // namespace plcemu::daemon
