// SPDX-License-Identifier: Apache-2.0
#pragma once
// Packet loss on a world link (the in-process one, inproc/inproc_world_link.h; the DDS one's delay stage,
// delay_stage.h): which frames and reports never arrive, drawn from a seeded generator so a lossy lockstep trial is
// bitwise repeatable.
//
// Gilbert–Elliott two-state model, the usual one for bursty network loss: in the good state nothing is lost, in the bad
// state everything is. The chain leaves the bad state with probability 1/B per packet (B: the mean burst length, in
// packets) and enters it with probability ℓ/(B(1 − ℓ)), so a fraction ℓ of the packets is lost over a long run. B = 1
// would forbid two losses in a row; independent (Bernoulli) loss is B = 1/(1 − ℓ), which burst_packets ≤ 1 selects.
//
// lose() never allocates, locks or throws (the 1 kHz servo calls it through the link); a rate of 0 draws nothing, so a
// loss-free link is the link without a loss model, bit for bit.

#include <cstdint>

namespace impetus {

struct LinkLoss {
  double rate = 0.0;           // ℓ, the fraction of packets lost, 0 ≤ ℓ < 1
  double burst_packets = 1.0;  // B, the mean run of consecutive losses; ≤ 1: independent losses
  std::uint64_t seed = 1;      // the generator's seed; each direction of each slot draws its own stream from it
};

class LossProcess {
 public:
  LossProcess() = default;
  // `stream` tells the directions and slots apart (a different sequence from the same seed).
  LossProcess(const LinkLoss& loss, std::uint64_t stream) : state_(loss.seed ^ (0x9E3779B97F4A7C15ull * (stream + 1))) {
    if (!(loss.rate > 0.0)) return;
    if (loss.burst_packets <= 1.0) {
      enter_bad_ = loss.rate;  // independent: every packet is lost with probability ℓ
      leave_bad_ = 1.0 - loss.rate;
    } else {
      leave_bad_ = 1.0 / loss.burst_packets;
      enter_bad_ = loss.rate * leave_bad_ / (1.0 - loss.rate);
    }
    active_ = true;
  }

  // Whether the next packet is lost.
  bool lose() {
    if (!active_) return false;
    const double u = uniform();
    bad_ = bad_ ? !(u < leave_bad_) : u < enter_bad_;
    if (bad_) ++lost_;
    return bad_;
  }
  std::uint64_t lost() const { return lost_; }

 private:
  // splitmix64: a fast generator with a 2^64 period, plenty for a loss stream; the top 53 bits give u ∈ [0, 1).
  double uniform() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return static_cast<double>(z >> 11) * 0x1.0p-53;
  }

  std::uint64_t state_ = 0;
  double enter_bad_ = 0.0;
  double leave_bad_ = 1.0;
  bool active_ = false;
  bool bad_ = false;
  std::uint64_t lost_ = 0;
};

}  // namespace impetus
