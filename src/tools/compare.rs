//! Comparing two renders: how many pixels differ, and by how much (`raystep diff`).

use std::path::Path;

use crate::error::Error;
use crate::io::scene_file::MAX_PIXELS;

/// How two images of the same size differ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Difference {
    /// Pixels compared.
    pub pixels: usize,
    /// Pixels where some channel differs by more than 1/255 (one 8-bit step).
    pub over_one_step: usize,
    /// The largest difference of any channel.
    pub largest: f32,
    /// Where it is: (row, column).
    pub largest_at: (usize, usize),
    /// Root mean square difference over every channel of every pixel where both
    /// images hold a finite number.
    pub rmse: f64,
    /// Pixels with some channel at 1 or more (clipped), in each image.
    pub saturated: (usize, usize),
    /// Pixels with some channel infinite or NaN, in each image.
    pub non_finite: (usize, usize),
}

/// How far apart two channels are: `|p − q|` where both are finite, 0 where both
/// are the same infinity or both NaN, and infinitely far where only one is finite
/// (or they are different infinities): a NaN where the other image has a number
/// is a difference, not an equality.
fn channel_difference(p: f32, q: f32) -> f32 {
    match (p.is_finite(), q.is_finite()) {
        (true, true) => (p - q).abs(),
        _ if p == q || (p.is_nan() && q.is_nan()) => 0.0,
        _ => f32::INFINITY,
    }
}

/// Compare two RGB images of `width` columns, pixel by pixel.
pub fn compare(a: &[[f32; 3]], b: &[[f32; 3]], width: usize) -> Difference {
    assert_eq!(a.len(), b.len(), "images of one size");
    let mut d = Difference {
        pixels: a.len(),
        over_one_step: 0,
        largest: 0.0,
        largest_at: (0, 0),
        rmse: 0.0,
        saturated: (0, 0),
        non_finite: (0, 0),
    };
    let (mut squares, mut finite) = (0.0f64, 0usize);
    for (i, (p, q)) in a.iter().zip(b).enumerate() {
        let worst = (0..3)
            .map(|c| channel_difference(p[c], q[c]))
            .fold(0.0, f32::max);
        for c in (0..3).filter(|&c| p[c].is_finite() && q[c].is_finite()) {
            squares += f64::from(p[c] - q[c]).powi(2);
            finite += 1;
        }
        d.non_finite.0 += usize::from(p.iter().any(|c| !c.is_finite()));
        d.non_finite.1 += usize::from(q.iter().any(|c| !c.is_finite()));
        if worst > 1.0 / 255.0 {
            d.over_one_step += 1;
        }
        if worst > d.largest {
            d.largest = worst;
            d.largest_at = (i / width, i % width);
        }
        d.saturated.0 += usize::from(p.iter().any(|&c| c >= 1.0));
        d.saturated.1 += usize::from(q.iter().any(|&c| c >= 1.0));
    }
    d.rmse = (squares / finite.max(1) as f64).sqrt();
    d
}

/// Pixels of two images of one size where some channel differs by more than
/// `tolerance` (a channel finite in one image and not in the other differs by
/// more than any tolerance): what `raystep diff --threshold` counts.
pub fn pixels_over(a: &[[f32; 3]], b: &[[f32; 3]], tolerance: f32) -> usize {
    assert_eq!(a.len(), b.len(), "images of one size");
    a.iter()
        .zip(b)
        .filter(|(p, q)| (0..3).any(|c| channel_difference(p[c], q[c]) > tolerance))
        .count()
}

/// The beauty (`R`, `G`, `B`) of a `buffers.exr` file: width, height, pixels.
///
/// The header is read first, and an image larger than raystep renders is refused
/// before any memory is taken for its pixels (a damaged or hostile header can claim
/// any size). Only the three colour channels are read.
pub fn read_beauty(path: &Path) -> Result<(usize, usize, Vec<[f32; 3]>), Error> {
    let fail = |message: String| Error::Scene {
        file: path.display().to_string(),
        message,
    };
    let not_exr = |e: exr::error::Error| fail(format!("cannot read it as an EXR file: {e}"));
    if path.as_os_str() == "-" {
        return Err(fail(
            "diff reads two EXR files by name; it does not read standard input".into(),
        ));
    }
    if path.is_dir() {
        return Err(fail(format!(
            "is a folder; diff compares two EXR files: {}",
            path.join(crate::io::output::EXR_FILE).display()
        )));
    }
    let meta = exr::meta::MetaData::read_from_file(path, false).map_err(not_exr)?;
    let largest = meta
        .headers
        .iter()
        .map(|h| h.layer_size.area() as u64)
        .max()
        .ok_or_else(|| fail("has no image layer".into()))?;
    // A real EXR file may hold no colour at all (a depth pass, say): say so, with
    // the channels it has, rather than that it is no EXR.
    let names = |h: &exr::meta::header::Header| -> Vec<String> {
        h.channels.list.iter().map(|c| c.name.to_string()).collect()
    };
    let coloured = |h: &exr::meta::header::Header| {
        let n = names(h);
        ["R", "G", "B"].iter().all(|c| n.iter().any(|m| m == c))
    };
    if !meta.headers.iter().any(coloured) {
        let has: Vec<String> = meta.headers.iter().flat_map(names).collect();
        return Err(fail(format!(
            "has no R, G and B channels (it has {}); raystep's buffers.exr has them",
            if has.is_empty() {
                "none".to_string()
            } else {
                has.join(", ")
            }
        )));
    }
    if largest > MAX_PIXELS {
        return Err(fail(format!(
            "holds an image of {largest} pixels; raystep compares at most {MAX_PIXELS}, \
             the most it renders"
        )));
    }
    use exr::prelude::{ReadChannels as _, ReadLayers as _};
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .rgb_channels(
            |size, _| (size.width(), vec![[0.0f32; 3]; size.area()]),
            |(width, pixels): &mut (usize, Vec<[f32; 3]>), at, (r, g, b): (f32, f32, f32)| {
                pixels[at.y() * *width + at.x()] = [r, g, b];
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| match e {
            exr::error::Error::Invalid(message) if message.contains("channel") => fail(format!(
                "has no R, G and B channels ({message}); raystep's buffers.exr has them"
            )),
            e => not_exr(e),
        })?;
    let size = image.layer_data.size;
    let (_, pixels) = image.layer_data.channel_data.pixels;
    Ok((size.width(), size.height(), pixels))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_differences_over_one_step_and_finds_the_largest() {
        let a = [
            [0.0, 0.0, 0.0],
            [0.5, 0.5, 0.5],
            [1.0, 0.2, 0.2],
            [0.3, 0.3, 0.3],
        ];
        let b = [
            [0.0, 0.0, 0.001],
            [0.5, 0.6, 0.5],
            [1.0, 0.2, 0.2],
            [0.3, 0.3, 0.0],
        ];
        let d = compare(&a, &b, 2);
        assert_eq!(d.over_one_step, 2);
        assert!((d.largest - 0.3).abs() < 1e-6);
        assert_eq!(d.largest_at, (1, 1));
        assert_eq!(d.saturated, (1, 1));
        let expected = ((0.001f64.powi(2) + 0.1f64.powi(2) + 0.3f64.powi(2)) / 12.0).sqrt();
        assert!((d.rmse - expected).abs() < 1e-6, "{}", d.rmse);
        assert_eq!(d.non_finite, (0, 0));
    }

    #[test]
    fn a_nan_or_an_infinity_beside_a_number_is_a_difference() {
        let a = [
            [0.5, 0.5, 0.5],
            [f32::NAN, 0.0, 0.0],
            [f32::INFINITY, 0.0, 0.0],
        ];
        let b = [[0.5, 0.5, 0.5], [0.2, 0.0, 0.0], [f32::INFINITY, 0.0, 0.0]];
        let d = compare(&a, &b, 3);
        assert_eq!(
            d.over_one_step, 1,
            "the NaN pixel differs, the same infinity not"
        );
        assert_eq!(d.largest, f32::INFINITY);
        assert_eq!(d.largest_at, (0, 1));
        assert_eq!(d.non_finite, (2, 1));
        assert!(d.rmse.is_finite() && d.rmse == 0.0, "{}", d.rmse);
        // Both NaN: the same.
        let d = compare(&[[f32::NAN; 3]], &[[f32::NAN; 3]], 1);
        assert_eq!((d.over_one_step, d.non_finite), (0, (1, 1)));
    }

    /// "More than 1/255": a channel off by exactly one 8-bit step (the float32
    /// nearest 1/255, against 0) does not count, one off by two steps does.
    #[test]
    fn a_difference_of_exactly_one_step_is_not_over_one_step() {
        let step = 1.0f32 / 255.0;
        let a = [[step, 0.0, 0.0], [0.0, 2.0 * step, 0.0]];
        let b = [[0.0; 3], [0.0; 3]];
        let d = compare(&a, &b, 2);
        assert_eq!(d.over_one_step, 1, "only the pixel two steps off");
        assert_eq!(pixels_over(&a, &b, step), 1);
        assert_eq!(
            pixels_over(&a, &b, 2.0 * step),
            0,
            "at the threshold, not over it"
        );
    }

    /// README: `largest_at` is "row 0, column 0 when nothing differs", whatever
    /// the size of the images.
    #[test]
    fn two_equal_images_place_the_largest_difference_at_row_0_column_0() {
        let a = [[0.25, 0.5, 0.75]; 6];
        let d = compare(&a, &a, 3);
        assert_eq!((d.largest, d.largest_at), (0.0, (0, 0)));
    }

    /// README: the RMSE is "over the channels finite in both files". Two pixels,
    /// one with a NaN in red: five channels finite in both, one of them 0.3 apart,
    /// so the RMSE is √(0.09 / 5) = 0.134164…, not √(0.09 / 6) = 0.122474….
    #[test]
    fn the_root_mean_square_is_over_the_channels_finite_in_both_images() {
        let a = [[f32::NAN, 0.0, 0.0], [0.3, 0.0, 0.0]];
        let b = [[0.0; 3], [0.0; 3]];
        let d = compare(&a, &b, 2);
        assert!((d.rmse - 0.134_164_08).abs() < 1e-6, "{}", d.rmse);
    }
}
