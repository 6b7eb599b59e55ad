//! The colour scale of the stress pictures (the PNG maps and `palpa serve`'s page, which takes
//! its colours from [`ColourScale::lut`], so both draw the same colours).
//!
//! The maximum principal stress under a press is a non-negative field almost everywhere, so the
//! scale is **sequential** from zero: ColorBrewer's YlOrRd (pale yellow at 0, dark red at the top;
//! Brewer & Harrower, "ColorBrewer.org", The Cartographic Journal 40 (2003) 27), whose lightness
//! falls monotonically, so that a value can be read back from a colour. Only when the range
//! holds negative values (compression) does it become **diverging**: the negative side takes
//! ColorBrewer's Blues from the same pale end. Both sides use the same slope,
//!
//! ```text
//! t = |v| / m,   m = max(-lo, hi),   colour = YlOrRd(t) for v >= 0, Blues(t) for v < 0,
//! ```
//!
//! so that 1 kPa of compression is as pale as 1 kPa of tension, and a small compressive range
//! stays pale instead of taking half the scale. The range is fixed by the caller (the model's
//! training range for a live view, so that colours mean the same thing from frame to frame);
//! values beyond it take the colour of its end. Colours are interpolated linearly in sRGB
//! between the nine classes of each scheme.

use serde::{Deserialize, Serialize};

/// ColorBrewer YlOrRd, 9 classes, from 0 to the top of the scale.
const YL_OR_RD: [[u8; 3]; 9] = [
    [255, 255, 204],
    [255, 237, 160],
    [254, 217, 118],
    [254, 178, 76],
    [253, 141, 60],
    [252, 78, 42],
    [227, 26, 28],
    [189, 0, 38],
    [128, 0, 38],
];

/// ColorBrewer Blues, 9 classes, from 0 to the bottom of the scale.
const BLUES: [[u8; 3]; 9] = [
    [247, 251, 255],
    [222, 235, 247],
    [198, 219, 239],
    [158, 202, 225],
    [107, 174, 214],
    [66, 146, 198],
    [33, 113, 181],
    [8, 81, 156],
    [8, 48, 107],
];

/// Sequential (non-negative range) or diverging (a range reaching below zero).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ScaleKind {
    /// YlOrRd from 0 to `hi`.
    Sequential,
    /// Blues below zero, YlOrRd above, same slope on both sides.
    Diverging,
}

/// A fixed colour scale over `[lo, hi]` (Pa), `lo <= 0 < hi`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ColourScale {
    /// Bottom of the scale (Pa): 0, or the most negative value of the range.
    pub lo: f64,
    /// Top of the scale (Pa).
    pub hi: f64,
}

impl ColourScale {
    /// The scale for values from `min` to `max` (Pa): it always starts at zero or below and
    /// ends above zero (a range without positive values gets a top of 1 Pa, so the scale
    /// stays defined).
    pub fn over(min: f64, max: f64) -> ColourScale {
        let lo = if min.is_finite() { min.min(0.0) } else { 0.0 };
        let hi = if max.is_finite() && max > 0.0 {
            max
        } else {
            1.0
        };
        ColourScale { lo, hi }
    }

    /// The scale for the values themselves (their own range).
    pub fn of_values(values: &[f64]) -> ColourScale {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for &v in values.iter().filter(|v| v.is_finite()) {
            lo = lo.min(v);
            hi = hi.max(v);
        }
        ColourScale::over(lo, hi)
    }

    /// Sequential or diverging.
    pub fn kind(&self) -> ScaleKind {
        if self.lo < 0.0 {
            ScaleKind::Diverging
        } else {
            ScaleKind::Sequential
        }
    }

    /// The colour of `v` (Pa); NaN gets mid grey.
    pub fn rgb(&self, v: f64) -> [u8; 3] {
        if v.is_nan() {
            return [128, 128, 128];
        }
        let v = v.clamp(self.lo, self.hi);
        let m = (-self.lo).max(self.hi);
        let t = (v.abs() / m).clamp(0.0, 1.0);
        if v >= 0.0 {
            interpolate(&YL_OR_RD, t)
        } else {
            interpolate(&BLUES, t)
        }
    }

    /// `n` colours at `lo + (hi - lo) k / (n - 1)`, k = 0 .. n-1: the page's lookup table.
    pub fn lut(&self, n: usize) -> Vec<[u8; 3]> {
        let n = n.max(2);
        (0..n)
            .map(|k| self.rgb(self.lo + (self.hi - self.lo) * k as f64 / (n - 1) as f64))
            .collect()
    }
}

fn interpolate(classes: &[[u8; 3]], t: f64) -> [u8; 3] {
    let f = t * (classes.len() - 1) as f64;
    let k = (f.floor() as usize).min(classes.len() - 2);
    let s = f - k as f64;
    let (a, b) = (classes[k], classes[k + 1]);
    [0, 1, 2].map(|c| (a[c] as f64 + s * (b[c] as f64 - a[c] as f64)).round() as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A non-negative range is sequential: zero is the pale end, the top the dark end, and
    /// the middle of the range falls on YlOrRd's middle class.
    #[test]
    fn sequential_for_a_non_negative_range() {
        let s = ColourScale::over(0.2e3, 14.0e3);
        assert_eq!(s.kind(), ScaleKind::Sequential);
        assert_eq!(
            s.lo, 0.0,
            "the scale starts at zero, not at the smallest value"
        );
        assert_eq!(s.rgb(0.0), [255, 255, 204]);
        assert_eq!(s.rgb(14.0e3), [128, 0, 38]);
        assert_eq!(s.rgb(7.0e3), [253, 141, 60]);
        assert_eq!(
            s.rgb(99.0e3),
            [128, 0, 38],
            "beyond the top: the top colour"
        );
    }

    /// A range reaching below zero is diverging with equal slopes: -1.5 kPa on a scale to
    /// 15 kPa is a tenth of the way into Blues (between classes 0 and 1: 0.8 of a class).
    #[test]
    fn diverging_with_equal_slopes() {
        let s = ColourScale::over(-1.5e3, 15.0e3);
        assert_eq!(s.kind(), ScaleKind::Diverging);
        // t = 0.1, f = 0.8 between [247,251,255] and [222,235,247]
        let expect = [
            (247.0 - 0.8 * 25.0_f64).round() as u8,
            (251.0 - 0.8 * 16.0_f64).round() as u8,
            (255.0 - 0.8 * 8.0_f64).round() as u8,
        ];
        assert_eq!(s.rgb(-1.5e3), expect);
        assert_eq!(s.rgb(15.0e3), [128, 0, 38]);
    }

    /// The lookup table spans the scale, ends included, and its YlOrRd part gets darker
    /// (sum of channels falls) as the value rises, so a colour reads back to one value.
    #[test]
    fn lut_is_monotonic_in_lightness() {
        let s = ColourScale::over(0.0, 10.0e3);
        let lut = s.lut(256);
        assert_eq!(lut.len(), 256);
        assert_eq!(lut[0], s.rgb(0.0));
        assert_eq!(lut[255], s.rgb(10.0e3));
        let light: Vec<u32> = lut
            .iter()
            .map(|c| c.iter().map(|&v| v as u32).sum())
            .collect();
        assert!(light.windows(2).all(|w| w[1] <= w[0]), "{light:?}");
    }

    /// Degenerate ranges still give a defined scale.
    #[test]
    fn degenerate_ranges() {
        assert_eq!(
            ColourScale::over(0.0, 0.0),
            ColourScale { lo: 0.0, hi: 1.0 }
        );
        assert_eq!(
            ColourScale::of_values(&[]),
            ColourScale { lo: 0.0, hi: 1.0 }
        );
        assert_eq!(
            ColourScale::of_values(&[-2.0, f64::NAN, 3.0]),
            ColourScale { lo: -2.0, hi: 3.0 }
        );
        assert_eq!(ColourScale::over(-5.0, -1.0).rgb(f64::NAN), [128, 128, 128]);
    }
}
