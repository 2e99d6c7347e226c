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

#[cfg(test)]
mod tests {
    use super::*;

    /// The mean of a series.
    fn mean(v: &[f64]) -> f64 {
        v.iter().sum::<f64>() / v.len() as f64
    }

    /// The correlation of two equally long series.
    fn correlation(a: &[f64], b: &[f64]) -> f64 {
        let (ma, mb) = (mean(a), mean(b));
        let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
        let var = |v: &[f64], m: f64| v.iter().map(|x| (x - m) * (x - m)).sum::<f64>();
        cov / (var(a, ma) * var(b, mb)).sqrt()
    }

    #[test]
    fn each_sample_jitters_freely_within_its_own_cell() {
        // 9 samples in each of 60 × 60 pixels: every sample in its own cell of
        // the 3 × 3 grid, its jitter (where in the cell) spread evenly over
        // [0, 1) (mean 1/2, variance 1/12), the row's and the column's jitters
        // unrelated, and each sample's unrelated to the next one's.
        let (n, spp) = (3u32, 9u32);
        let (mut rows, mut cols, mut next_rows) = (Vec::new(), Vec::new(), Vec::new());
        for row in 0..60 {
            for col in 0..60 {
                let jitter = |sample: u32| {
                    let (y, x) = stratified(row, col, sample, spp);
                    let cell_y = (y - f64::from(row) + 0.5) * f64::from(n);
                    let cell_x = (x - f64::from(col) + 0.5) * f64::from(n);
                    let (jy, jx) = (
                        cell_y - f64::from(sample / n),
                        cell_x - f64::from(sample % n),
                    );
                    assert!((0.0..1.0).contains(&jy) && (0.0..1.0).contains(&jx));
                    (jy, jx)
                };
                for sample in 0..spp - 1 {
                    let (jy, jx) = jitter(sample);
                    rows.push(jy);
                    cols.push(jx);
                    next_rows.push(jitter(sample + 1).0);
                }
            }
        }
        let mean = mean(&rows);
        let variance =
            rows.iter().map(|j| (j - mean) * (j - mean)).sum::<f64>() / rows.len() as f64;
        assert!((mean - 0.5).abs() < 0.01, "mean jitter {mean}");
        assert!((variance - 1.0 / 12.0).abs() < 0.005, "variance {variance}");
        for (what, r) in [
            ("row and column", correlation(&rows, &cols)),
            ("one sample and the next", correlation(&rows, &next_rows)),
        ] {
            assert!(r.abs() < 0.03, "{what}: correlation {r}");
        }
    }

    #[test]
    fn only_square_sample_counts_from_1_to_1024_are_accepted() {
        for spp in [1, 4, 9, 16, 1024] {
            assert!(check_spp(spp).is_ok(), "{spp}");
        }
        for spp in [0, 2, 5, 8, 1023, 1025] {
            assert!(check_spp(spp).is_err(), "{spp}");
        }
        let said = check_spp(5).unwrap_err();
        assert!(said.contains("the nearest are 4 and 9"), "{said}");
    }
}
