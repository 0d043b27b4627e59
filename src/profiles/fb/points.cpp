#include "profiles/fb/points.hpp"

namespace plcemu::profiles::fb {

void Point::add(int sample) noexcept {
    samples_[static_cast<std::size_t>(next_)] = sample;
    next_ = (next_ + 1) % kMaxSamples;
    if (count_ < kMaxSamples) ++count_;
}

long long Point::sum(int n) const noexcept {
    long long s = 0;
    const int k = used(n);
    for (int i = 1; i <= k; ++i) {
        s += samples_[static_cast<std::size_t>((next_ - i + kMaxSamples) % kMaxSamples)];
    }
    return s;
}

}  // namespace plcemu::profiles::fb
