//! Seed mixing: how Kinergy turns one user seed into many independent streams, in one place.
//!
//! Everything here is built on SplitMix64 (Steele, Lea & Flood 2014, "Fast splittable
//! pseudorandom number generators", OOPSLA): its state advances by the golden gamma
//! [`GOLDEN_GAMMA`] (a Weyl sequence, [`weyl`]) and each state goes through a bijective
//! 64-bit finaliser ([`finalize`]: xor-shift 30, multiply, xor-shift 27, multiply,
//! xor-shift 31 — Stafford's "Mix13"), whose every output bit depends on every input bit.
//! [`splitmix64`] is one step of the generator (advance, then finalise); [`mix`] finalises a
//! seed combined with two indices ([`combine`]), so nearby indices give unrelated seeds.
//!
//! The callers' schemes, each kept bit for bit (files and outputs made with a seed stay the
//! same):
//!
//! - the annealer's generator of member `m` at iteration `k`:
//!   `splitmix64(seed ^ splitmix64(k ^ splitmix64(m ^ C)))`;
//! - the nested fit's seed per model: `combine(seed, k, 0)`, `k` = 1…5 for S_A…S_E (and S_E's first phase mixes its seed once more with `k` = 1);
//! - the synthetic set's per-person and per-reach seeds: `mix(seed, person, reach)`;
//! - the planner's seed per phase: `weyl(salt, seed)`.
//!
//! ```
//! use kinergy_motion::seed::{combine, finalize, mix, splitmix64, weyl, GOLDEN_GAMMA};
//!
//! assert_eq!(splitmix64(0), 0xe220_a839_7b1d_cdaf); // the generator's first output from 0
//! assert_eq!(splitmix64(7), finalize(weyl(7, 1)));
//! assert_eq!(mix(7, 1, 2), finalize(combine(7, 1, 2)));
//! assert_eq!(combine(7, 3, 0), 7 ^ 3u64.wrapping_mul(GOLDEN_GAMMA));
//! ```

/// The golden gamma, ⌊2⁶⁴/φ⌋ made odd: SplitMix64's state increment.
pub const GOLDEN_GAMMA: u64 = 0x9e37_79b9_7f4a_7c15;

/// A second odd constant for a second index in [`combine`], so that `(a, b)` and `(b, a)`
/// differ.
pub const SECOND_GAMMA: u64 = 0xd1b5_4a32_d192_ed03;

/// SplitMix64's finaliser (Mix13): a bijective mix of 64 bits.
#[inline]
pub fn finalize(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The Weyl sequence SplitMix64's state follows: `start + n · GOLDEN_GAMMA` (wrapping), the
/// state `n` steps after `start`.
#[inline]
pub fn weyl(start: u64, n: u64) -> u64 {
    n.wrapping_mul(GOLDEN_GAMMA).wrapping_add(start)
}

/// One SplitMix64 step from state `z`: the output `finalize(z + GOLDEN_GAMMA)`.
#[inline]
pub fn splitmix64(z: u64) -> u64 {
    finalize(weyl(z, 1))
}

/// `seed` with two indices folded in, not yet finalised: `seed ^ a · GOLDEN_GAMMA ^ b ·
/// SECOND_GAMMA` (wrapping products).
#[inline]
pub fn combine(seed: u64, a: u64, b: u64) -> u64 {
    seed ^ a.wrapping_mul(GOLDEN_GAMMA) ^ b.wrapping_mul(SECOND_GAMMA)
}

/// An independent seed for indices `(a, b)` under `seed`: `finalize(combine(seed, a, b))`.
#[inline]
pub fn mix(seed: u64, a: u64, b: u64) -> u64 {
    finalize(combine(seed, a, b))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// kinergy-reach's `synth::mix` as it is written there, to check [`mix`] against.
    fn reach_mix(seed: u64, a: u64, b: u64) -> u64 {
        let mut z =
            seed ^ a.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ b.wrapping_mul(0xd1b5_4a32_d192_ed03);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// kinergy-train's annealer `splitmix64` as it was written there.
    fn train_splitmix64(mut z: u64) -> u64 {
        z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    const INPUTS: [u64; 6] = [0, 1, 2, 42, 0x6b69_6e65_7267_7921, u64::MAX];

    #[test]
    fn mix_is_reachs_synthetic_set_mix() {
        for seed in INPUTS {
            for a in [0, 1, 7, u64::MAX] {
                for b in [0, 3, 1 << 40] {
                    assert_eq!(mix(seed, a, b), reach_mix(seed, a, b), "{seed} {a} {b}");
                }
            }
        }
        // Values the synthetic set's default seed gives today.
        assert_eq!(mix(42, 1, 0), reach_mix(42, 1, 0));
        assert_ne!(mix(42, 1, 2), mix(42, 2, 1));
    }

    #[test]
    fn splitmix64_is_the_annealers_and_the_reference() {
        for z in INPUTS {
            assert_eq!(splitmix64(z), train_splitmix64(z), "{z}");
        }
        // The first outputs of SplitMix64 seeded with 0 (Vigna's reference splitmix64.c).
        assert_eq!(splitmix64(0), 0xe220_a839_7b1d_cdaf);
        assert_eq!(splitmix64(GOLDEN_GAMMA), 0x6e78_9e6a_a1b9_65f4);
    }

    #[test]
    fn weyl_and_combine_are_the_plain_formulas() {
        for s in INPUTS {
            for n in [0, 1, 5, u64::MAX] {
                assert_eq!(weyl(n, s), s.wrapping_mul(GOLDEN_GAMMA).wrapping_add(n));
                assert_eq!(combine(s, n, 0), s ^ n.wrapping_mul(GOLDEN_GAMMA));
            }
        }
    }
}
