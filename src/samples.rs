//! Where the samples of a pixel go (`--spp`): jittered points of a grid over the
//! pixel, the same on every run. The book's row loop averages their colours
//! ([`samples_mean`](crate::render::samples_mean)), outside
//! [`Tracer::pixel`](crate::render::Tracer::pixel): the pixel's own centre ray
//! still gives the buffers, so they read the same whatever the sample count.

// ANCHOR: stratified
/// Sample `sample` of `spp` (a square, n × n) in pixel (`row`, `col`): the top-left
/// corner of one cell of an n × n grid over the pixel, moved by a jitter within the cell.
/// The jitter comes from a hash of the pixel and the sample, so every render gives
/// the same samples. Returns the position in fractional rows and columns.
pub fn stratified(row: u32, col: u32, sample: u32, spp: u32) -> (f64, f64) {
    let n = spp.isqrt();
    let (sy, sx) = (sample / n, sample % n);
    let bits = splitmix64(u64::from(row) << 40 ^ u64::from(col) << 20 ^ u64::from(sample));
    let (jy, jx) = (unit_interval(bits), unit_interval(splitmix64(bits)));
    let n = f64::from(n);
    (
        f64::from(row) - 0.5 + (f64::from(sy) + jy) / n,
        f64::from(col) - 0.5 + (f64::from(sx) + jx) / n,
    )
}
// ANCHOR_END: stratified

/// A number in [0, 1) from the top 53 bits of `bits`: every float64 of the form
/// k / 2⁵³, equally likely.
pub fn unit_interval(bits: u64) -> f64 {
    (bits >> 11) as f64 / (1u64 << 53) as f64
}

/// SplitMix64 (Steele, Lea and Flood, 2014): a 64-bit hash whose outputs pass
/// the usual statistical tests; one step of it turns a pixel's coordinates and
/// sample number into the row jitter, a second step into the column jitter.
pub fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Most samples per pixel (`--spp`): 32 × 32.
pub const MAX_SPP: u32 = 1024;

/// Refuse a sample count that is not a square from 1 to [`MAX_SPP`] (the samples
/// of a pixel form an n × n grid of strata).
pub fn check_spp(spp: u32) -> Result<(), String> {
    let n = spp.isqrt();
    if !(1..=MAX_SPP).contains(&spp) {
        Err(format!("--spp {spp}: must be from 1 to {MAX_SPP}"))
    } else if n * n != spp {
        Err(format!(
            "--spp {spp}: must be a square number (1, 4, 9, 16, …), so that the samples \
             form an n × n grid over the pixel; the nearest are {} and {}",
            n * n,
            (n + 1) * (n + 1)
        ))
    } else {
        Ok(())
    }
}
