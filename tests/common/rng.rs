//! A small deterministic generator (xorshift64*) for test data and mutations.

pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    /// Uniform in `0..n` (0 when `n` is 0).
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next() % n as u64) as usize
        }
    }
    pub fn byte(&mut self) -> u8 {
        (self.next() >> 56) as u8
    }
    pub fn bytes(&mut self, n: usize) -> Vec<u8> {
        (0..n).map(|_| self.byte()).collect()
    }
}

/// Deterministic pseudo-random numbers in [0, 1) (xorshift-multiply hash).
pub fn hash01(mut k: u64) -> f32 {
    k ^= k >> 33;
    k = k.wrapping_mul(0xff51_afd7_ed55_8ccd);
    k ^= k >> 33;
    k = k.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    k ^= k >> 33;
    (k >> 40) as f32 / (1u64 << 24) as f32
}

/// Deterministic zero-mean noise with standard deviation `sigma` (sum of 4 uniforms).
pub fn noise(seed: u64, sigma: f32) -> f32 {
    let s: f32 = (0..4).map(|i| hash01(seed * 4 + i)).sum::<f32>() - 2.0;
    // Var of a sum of 4 U(0,1) is 4/12 = 1/3.
    s * sigma * 3f32.sqrt()
}
