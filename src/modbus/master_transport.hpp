#pragma once
// A Modbus master's wire, as the event loop drives it: one transaction at a time, sent to a
// station, ended by a reply, by its deadline or by something that is no frame. TCP (MBAP) and
// RTU (t3.5, CRC) each implement it; the PDU inside is master_pdu's business.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <utility>

namespace plcemu::modbus {

/// How a transaction ended on the wire.
enum class MasterOutcome : std::uint8_t {
    Reply,     ///< a frame from the station answering this transaction
    TimedOut,  ///< nothing by the deadline (no connection, a closed one, a silent station)
    Garbled,   ///< bytes that are no frame (a bad MBAP header, a bad CRC, another unit)
    Sent,      ///< a broadcast (station 0) went out: no station answers one
};

/// Called once, on the loop, with the outcome and the reply PDU (Reply only; valid during the
/// call).
using MasterDone = std::function<void(MasterOutcome, std::span<const std::uint8_t>)>;

/// One master port.
class MasterTransport {
public:
    virtual ~MasterTransport() = default;
    /// Sends `pdu` to `station`; `done` is called by `timeout` (real time) at the latest. A new
    /// transaction abandons the one in flight.
    virtual void transact(std::uint8_t station,
                          std::span<const std::uint8_t> pdu,
                          std::chrono::milliseconds timeout,
                          MasterDone done) = 0;
    /// Abandons the transaction in flight: its `done` is never called, a late reply is dropped.
    virtual void cancel() noexcept = 0;
    /// Closes everything; nothing is called after.
    virtual void stop() noexcept = 0;
    /// Where requests go, as logged.
    virtual std::string description() const = 0;
};

/// A master port whose state lives in an object shared with the handlers it has pending on the
/// loop, so that a handler that runs after the port is gone finds the state stopped, not freed.
/// `State` has transact, cancel, stop (which may be called again) and description, and is
/// complete where the port's constructor and destructor are defined.
template <class State>
class SharedStateTransport : public MasterTransport {
public:
    ~SharedStateTransport() override { state_->stop(); }
    SharedStateTransport(const SharedStateTransport&) = delete;
    SharedStateTransport& operator=(const SharedStateTransport&) = delete;

    void transact(std::uint8_t station,
                  std::span<const std::uint8_t> pdu,
                  std::chrono::milliseconds timeout,
                  MasterDone done) override {
        state_->transact(station, pdu, timeout, std::move(done));
    }
    void cancel() noexcept override { state_->cancel(); }
    void stop() noexcept override { state_->stop(); }
    std::string description() const override { return state_->description(); }

protected:
    explicit SharedStateTransport(std::shared_ptr<State> state)
        : state_(std::move(state)) {}

    std::shared_ptr<State> state_;  ///< never null
};

}  // namespace plcemu::modbus
