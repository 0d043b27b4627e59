// The bit-logic statements of a listing (plcemu/instructions/listing.hpp).

#include "rung.hpp"

#include <string>
#include <type_traits>
#include <utility>

#include "edge.hpp"

namespace plcemu::instructions {

namespace {

struct Unused {};

// A contact: reads its source, then joins it to the rung. A value entering the rung from a
// device is gated by master control, so every coil between an MC that is OFF and its MCR sees
// OFF (an OUT turns off, a timer resets; a SET or a counter keeps), as on the FX family.
template <Contact kind>
class ContactStep final : public engine::Instruction {
public:
    ContactStep(std::shared_ptr<Rung> rung,
                std::string_view mnemonic,
                Join join,
                int depth,
                const ContactSource& source)
        : rung_(std::move(rung)),
          mnemonic_(mnemonic),
          join_(join),
          depth_(depth),
          source_(source) {}

    void execute(engine::ScanContext& ctx) noexcept override {
        const bool v = value(ctx.image, ctx.first_scan);
        Rung& r = *rung_;
        switch (join_) {
            case Join::Start:
                r.result = v && r.enabled;
                break;
            case Join::Block:
                r.blocks[static_cast<std::size_t>(depth_)] = r.result;
                r.result = v && r.enabled;
                break;
            case Join::And:
                r.result = r.result && v;
                break;
            case Join::Or:
                r.result = (r.result || v) && r.enabled;
                break;
        }
    }

    std::string_view mnemonic() const noexcept override { return mnemonic_; }

private:
    bool value(const image::Image& img, bool first_scan) noexcept {
        if constexpr (kind == Contact::Compare) {
            return holds(source_.relation, static_cast<std::int16_t>(source_.s1.read(img)),
                         static_cast<std::int16_t>(source_.s2.read(img)));
        } else {
            const bool in = img.read_bit(source_.device);
            if constexpr (kind == Contact::Open) return in;
            if constexpr (kind == Contact::Closed) return !in;
            if constexpr (kind == Contact::Rising || kind == Contact::Falling)
                return edge_(in, first_scan);
        }
    }

    std::shared_ptr<Rung> rung_;
    std::string_view mnemonic_;
    Join join_;
    int depth_;
    ContactSource source_;
    // Only an edge contact remembers its device from the scan before.
    using Edge =
        std::conditional_t<kind == Contact::Rising,
                           RisingEdge,
                           std::conditional_t<kind == Contact::Falling, FallingEdge, Unused>>;
    [[no_unique_address]] Edge edge_;
};

class RungStep final : public engine::Instruction {
public:
    RungStep(std::shared_ptr<Rung> rung, std::string_view mnemonic, RungOp op, int depth)
        : rung_(std::move(rung)),
          mnemonic_(mnemonic),
          op_(op),
          at_(static_cast<std::size_t>(depth)) {}

    void execute(engine::ScanContext& ctx) noexcept override {
        Rung& r = *rung_;
        switch (op_) {
            case RungOp::AndBlock:
                r.result = r.blocks[at_] && r.result;
                break;
            case RungOp::OrBlock:
                r.result = r.blocks[at_] || r.result;
                break;
            case RungOp::Push:
                r.branches[at_] = r.result;
                break;
            case RungOp::Read:
                r.result = r.branches[at_];
                break;
            case RungOp::Invert:
                r.result = !r.result && r.enabled;
                break;
            case RungOp::Rising:
                r.result = rising_(r.result, ctx.first_scan);
                break;
            case RungOp::Falling:
                r.result = falling_(r.result, ctx.first_scan);
                break;
            case RungOp::Save:
                r.saved[at_] = r.result;
                break;
            case RungOp::Restore:
                r.result = r.saved[at_];
                break;
        }
    }

    std::string_view mnemonic() const noexcept override { return mnemonic_; }

private:
    std::shared_ptr<Rung> rung_;
    std::string_view mnemonic_;
    RungOp op_;
    std::size_t at_;
    RisingEdge rising_;    // TU's
    FallingEdge falling_;  // TD's
};

class CoilStep final : public engine::Instruction {
public:
    CoilStep(std::shared_ptr<Rung> rung, std::string_view mnemonic, CoilOp op, image::Device d)
        : rung_(std::move(rung)),
          mnemonic_(mnemonic),
          op_(op),
          d_(d) {}

    void execute(engine::ScanContext& ctx) noexcept override {
        const bool v = rung_->result;
        switch (op_) {
            case CoilOp::Out:
                ctx.image.write_bit(d_, v);
                break;
            case CoilOp::OutNot:
                // Inverted, but still OFF while master control holds the rung OFF.
                ctx.image.write_bit(d_, !v && rung_->enabled);
                break;
            case CoilOp::Set:
                if (v) ctx.image.write_bit(d_, true);
                break;
            case CoilOp::SetOnRising:
                if (edge_(v, ctx.first_scan)) ctx.image.write_bit(d_, true);
                break;
        }
    }

    std::string_view mnemonic() const noexcept override { return mnemonic_; }

private:
    std::shared_ptr<Rung> rung_;
    std::string_view mnemonic_;
    CoilOp op_;
    image::Device d_;
    RisingEdge edge_;  // SET P's
};

class MasterControl final : public engine::Instruction {
public:
    MasterControl(std::shared_ptr<Rung> rung, int slot, image::Device coil)
        : rung_(std::move(rung)),
          slot_(static_cast<std::size_t>(slot)),
          coil_(coil) {}

    void execute(engine::ScanContext& ctx) noexcept override {
        Rung& r = *rung_;
        const bool on = r.result && r.enabled;
        ctx.image.write_bit(coil_, on);
        r.levels[slot_ + 1] = on;
        r.enabled = on;
    }

    std::string_view mnemonic() const noexcept override { return "MC"; }

private:
    std::shared_ptr<Rung> rung_;
    std::size_t slot_;
    image::Device coil_;
};

class MasterReset final : public engine::Instruction {
public:
    MasterReset(std::shared_ptr<Rung> rung, int slot)
        : rung_(std::move(rung)),
          slot_(static_cast<std::size_t>(slot)) {}

    void execute(engine::ScanContext& /*ctx*/) noexcept override {
        rung_->enabled = rung_->levels[slot_];
    }

    std::string_view mnemonic() const noexcept override { return "MCR"; }

private:
    std::shared_ptr<Rung> rung_;
    std::size_t slot_;
};

}  // namespace

std::unique_ptr<engine::Instruction> make_contact(std::shared_ptr<Rung> rung,
                                                  std::string_view mnemonic,
                                                  Join join,
                                                  int depth,
                                                  const ContactSource& source) {
    switch (source.contact) {
        case Contact::Open:
            return std::make_unique<ContactStep<Contact::Open>>(std::move(rung), mnemonic, join,
                                                                depth, source);
        case Contact::Closed:
            return std::make_unique<ContactStep<Contact::Closed>>(std::move(rung), mnemonic, join,
                                                                  depth, source);
        case Contact::Rising:
            return std::make_unique<ContactStep<Contact::Rising>>(std::move(rung), mnemonic, join,
                                                                  depth, source);
        case Contact::Falling:
            return std::make_unique<ContactStep<Contact::Falling>>(std::move(rung), mnemonic, join,
                                                                   depth, source);
        case Contact::Compare:
            break;
    }
    return std::make_unique<ContactStep<Contact::Compare>>(std::move(rung), mnemonic, join, depth,
                                                           source);
}

std::unique_ptr<engine::Instruction> make_rung_op(std::shared_ptr<Rung> rung,
                                                  std::string_view mnemonic,
                                                  RungOp op,
                                                  int depth) {
    return std::make_unique<RungStep>(std::move(rung), mnemonic, op, depth);
}

std::unique_ptr<engine::Instruction> make_coil(std::shared_ptr<Rung> rung,
                                               std::string_view mnemonic,
                                               CoilOp op,
                                               image::Device device) {
    return std::make_unique<CoilStep>(std::move(rung), mnemonic, op, device);
}

std::unique_ptr<engine::Instruction> make_master_control(std::shared_ptr<Rung> rung,
                                                         int slot,
                                                         image::Device coil) {
    return std::make_unique<MasterControl>(std::move(rung), slot, coil);
}

std::unique_ptr<engine::Instruction> make_master_reset(std::shared_ptr<Rung> rung, int slot) {
    return std::make_unique<MasterReset>(std::move(rung), slot);
}

}  // namespace plcemu::instructions
