#include "from_to.hpp"

#include <optional>

#include "edge.hpp"
#include "operands.hpp"

namespace plcemu::instructions {

namespace {

enum class Direction : std::uint8_t { From, To };

class Transfer final : public engine::Instruction {
public:
    Transfer(Direction dir,
             BitSource en,
             bool pulse,
             WordSource module,
             WordSource word,
             WordSource data,  // FROM: the first destination; TO: the source
             std::uint32_t n,
             std::optional<OperationError> error,
             int index)
        : dir_(dir),
          en_(en),
          pulse_(pulse),
          module_(module),
          word_(word),
          data_(data),
          n_(n),
          error_(error),
          index_(index) {}

    void execute(engine::ScanContext& ctx) noexcept override {
        const bool on = en_.read(ctx.image);
        if (!(pulse_ ? edge_(on, ctx.first_scan) : on)) return;
        image::Image& img = ctx.image;
        const int module = static_cast<std::int16_t>(module_.read(img));
        const int first = static_cast<std::int16_t>(word_.read(img));
        for (std::uint32_t i = 0; i < n_; ++i) {
            const int w = first + static_cast<int>(i);
            image::Device d = data_.device;
            d.index += i * (d.word_of_bits ? 16u : 1u);
            bool ok = ctx.modules != nullptr;
            if (ok && dir_ == Direction::From) {
                std::uint16_t v = 0;
                ok = ctx.modules->read(module, w, v);
                if (ok) img.write_word(d, v);
            } else if (ok) {
                ok = ctx.modules->write(module, w, data_.constant ? data_.value : img.read_word(d));
            }
            if (!ok) {
                // The words before the missing one have moved, as on the PLC.
                // A module or buffer word that does not exist: the family's operand error
                // (docs/profile-vb.md, "Temperature modules").
                if (error_) error_->raise(img, error_->operand_error, index_);
                return;
            }
        }
    }

    std::string_view mnemonic() const noexcept override {
        return dir_ == Direction::From ? "FROM" : "TO";
    }

private:
    Direction dir_;
    BitSource en_;
    bool pulse_;
    WordSource module_;
    WordSource word_;
    WordSource data_;
    std::uint32_t n_;
    std::optional<OperationError> error_;
    int index_;
    RisingEdge edge_;  // the pulse form's
};

// Buffer words one FROM/TO moves at most.
constexpr long long kMaxWords = 512;

std::unique_ptr<engine::Instruction> make(Direction dir, const Entry& ic, const BindContext& ctx) {
    Operands ops(ic, ctx);
    const BitSource en = ops.bit_source("en", true);
    const bool pulse = ops.flag("p", false);
    const WordSource module = ops.word_source("m1");
    const WordSource word = ops.word_source("m2");
    const auto n = static_cast<std::uint32_t>(ops.has("n") ? ops.integer("n", 1, kMaxWords) : 1);
    WordSource data;
    if (dir == Direction::From) {
        data.device =
            ops.output_words("d", n,
                             {image::Area::R, image::Area::D, image::Area::M, image::Area::Y,
                              image::Area::S, image::Area::TV, image::Area::CV});
    } else if (ops.numeric("s")) {
        data = ops.word_source("s");
    } else {
        data.device =
            ops.word_device("s", n,
                            {image::Area::R, image::Area::D, image::Area::M, image::Area::Y,
                             image::Area::X, image::Area::S, image::Area::TV, image::Area::CV});
    }
    ops.finish();
    return std::make_unique<Transfer>(dir, en, pulse, module, word, data, n,
                                      ctx.services.operation_error, ic.index);
}

}  // namespace

std::unique_ptr<engine::Instruction> make_from(const Entry& ic, const BindContext& ctx) {
    return make(Direction::From, ic, ctx);
}

std::unique_ptr<engine::Instruction> make_to(const Entry& ic, const BindContext& ctx) {
    return make(Direction::To, ic, ctx);
}

}  // namespace plcemu::instructions
