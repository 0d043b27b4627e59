#include "master_link.hpp"

#include <spdlog/spdlog.h>

#include "modbus/rtu_master.hpp"
#include "modbus/tcp_master.hpp"

namespace plcemu::daemon {

namespace {

// The config checked the addresses (vb::read_mbus).
asio::ip::tcp::endpoint endpoint_of(const config::TcpEndpoint& e) {
    return {asio::ip::make_address(e.host), e.port};
}

}  // namespace

MasterLink::MasterLink(std::unique_ptr<modbus::MasterTransport> transport)
    : transport_(std::move(transport)) {}

MasterLink::~MasterLink() { transport_->stop(); }

bool MasterLink::submit(const engine::OutboundRequest& r) noexcept {
    if (busy_) return false;
    request_size_ = modbus::encode_request(r.function, r.address, r.quantity,
                                           {r.values.data(), r.quantity}, request_);
    result_.reset();
    busy_ = true;
    if (request_size_ == 0) {
        result_ = engine::OutboundCompletion{engine::OutboundStatus::Malformed, 0, {}};
        return true;
    }
    try {
        transport_->transact(r.station, {request_.data(), request_size_}, r.timeout,
                             [this](modbus::MasterOutcome o, std::span<const std::uint8_t> pdu) {
                                 on_done(o, pdu);
                             });
    } catch (const std::exception& e) {
        // Out of memory for the frame: the transfer counts as unanswered.
        spdlog::warn("mbus: request not sent: {}", e.what());
        result_ = engine::OutboundCompletion{};
    }
    return true;
}

void MasterLink::on_done(modbus::MasterOutcome outcome,
                         std::span<const std::uint8_t> pdu) noexcept {
    if (!busy_) return;
    engine::OutboundCompletion c;
    switch (outcome) {
        case modbus::MasterOutcome::TimedOut:
            c.status = engine::OutboundStatus::TimedOut;
            break;
        case modbus::MasterOutcome::Garbled:
            c.status = engine::OutboundStatus::Malformed;
            break;
        case modbus::MasterOutcome::Sent:
            // A broadcast write is done once sent; nobody answers a broadcast read.
            c.status = modbus::is_write(request_[0]) ? engine::OutboundStatus::Reply
                                                     : engine::OutboundStatus::TimedOut;
            break;
        case modbus::MasterOutcome::Reply: {
            const auto check = modbus::check_reply({request_.data(), request_size_}, pdu, c.values);
            c.status = check.verdict == modbus::ReplyVerdict::Ok ? engine::OutboundStatus::Reply
                       : check.verdict == modbus::ReplyVerdict::Exception
                           ? engine::OutboundStatus::Exception
                           : engine::OutboundStatus::Malformed;
            c.exception = check.exception;
            break;
        }
    }
    result_ = c;
}

std::optional<engine::OutboundCompletion> MasterLink::poll() noexcept {
    if (!busy_ || !result_) return std::nullopt;
    busy_ = false;
    auto c = result_;
    result_.reset();
    return c;
}

void MasterLink::abandon() noexcept {
    transport_->cancel();
    busy_ = false;
    result_.reset();
}

std::unique_ptr<MasterLink> open_master_link(asio::io_context& io,
                                             const config::MasterConfig& config,
                                             bool strict) {
    if (config.transport == config::MasterTransport::Rtu) {
        const config::RtuConfig& r = *config.rtu;
        return std::make_unique<MasterLink>(std::make_unique<modbus::RtuMaster>(
            io, modbus::RtuOptions{r.device, r.baud, r.parity, r.data_bits, r.stop_bits},
            strict ? modbus::RtuMaster::Open::Now : modbus::RtuMaster::Open::Lazily));
    }
    modbus::TcpMasterOptions o;
    if (!config.tcp.host.empty()) o.fallback = endpoint_of(config.tcp);
    for (const auto& r : config.routes) o.routes.emplace_back(r.station, endpoint_of(r.endpoint));
    return std::make_unique<MasterLink>(std::make_unique<modbus::TcpMaster>(io, std::move(o)));
}

}  // namespace plcemu::daemon
