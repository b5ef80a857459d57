//! Colour: sRGB and linear RGB (sRGB primaries, D65), CIE XYZ, CIE L*a*b* (D65 white) and the
//! CIEDE2000 colour difference.
//!
//! - sRGB's transfer function and primaries: IEC 61966-2-1:1999 (the matrix to XYZ to four
//!   decimals, as the standard gives it).
//! - L*a*b*: CIE 15:2004, with the reference white the sRGB matrix's image of linear (1, 1, 1), so
//!   that sRGB white is L* = 100, a* = b* = 0 exactly (it is D65, x = 0.3127, y = 0.3290, to the
//!   matrix's four decimals).
//! - CIEDE2000: Sharma, Wu and Dalal 2005, "The CIEDE2000 color-difference formula: implementation
//!   notes, supplementary test data, and mathematical observations" (Color Res. Appl. 30(1)),
//!   equations (1)-(17), with k_L = k_C = k_H = 1.
//!
//! Everything is `f64`: a per-texel error map of a print is a few hundred thousand differences,
//! and the paper's test data is given to four decimals.

use std::sync::LazyLock;

/// Linear RGB with sRGB's primaries and white (D65): what a renderer's film holds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearRgb(pub [f64; 3]);

/// sRGB-encoded RGB in [0, 1] (8-bit image values / 255).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Srgb(pub [f64; 3]);

/// CIE 1931 XYZ, Y = 1 for the white.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Xyz(pub [f64; 3]);

/// CIE 1976 L*a*b* relative to [`white`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lab {
    pub l: f64,
    pub a: f64,
    pub b: f64,
}

/// Linear sRGB to XYZ (IEC 61966-2-1, rows X, Y, Z).
const RGB_TO_XYZ: [[f64; 3]; 3] = [
    [0.4124, 0.3576, 0.1805],
    [0.2126, 0.7152, 0.0722],
    [0.0193, 0.1192, 0.9505],
];

/// Its inverse, derived rather than typed in, so that the round trip is exact to rounding.
static XYZ_TO_RGB: LazyLock<[[f64; 3]; 3]> = LazyLock::new(|| invert(&RGB_TO_XYZ));

/// The reference white of L*a*b*: linear RGB (1, 1, 1) in XYZ.
pub fn white() -> Xyz {
    LinearRgb([1.0; 3]).to_xyz()
}

impl Srgb {
    /// From 8-bit values.
    pub fn from_u8(c: [u8; 3]) -> Srgb {
        Srgb(c.map(|v| f64::from(v) / 255.0))
    }

    /// To 8-bit values, rounded, clamped to [0, 255].
    pub fn to_u8(self) -> [u8; 3] {
        self.0.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
    }

    /// sRGB's decoding (its piecewise transfer function, inverted), odd-symmetric about 0 as
    /// [`LinearRgb::to_srgb`] is.
    pub fn to_linear(self) -> LinearRgb {
        LinearRgb(self.0.map(|c| {
            let m = c.abs();
            let l = if m <= 0.04045 {
                m / 12.92
            } else {
                ((m + 0.055) / 1.055).powf(2.4)
            };
            l.copysign(c)
        }))
    }
}

impl LinearRgb {
    /// sRGB's encoding; negative values encode as their sign times the encoding of the magnitude,
    /// so that out-of-gamut colours round-trip.
    pub fn to_srgb(self) -> Srgb {
        Srgb(self.0.map(|v| {
            let m = v.abs();
            let e = if m <= 0.0031308 {
                12.92 * m
            } else {
                1.055 * m.powf(1.0 / 2.4) - 0.055
            };
            e.copysign(v)
        }))
    }

    pub fn to_xyz(self) -> Xyz {
        Xyz(mul(&RGB_TO_XYZ, self.0))
    }

    pub fn to_lab(self) -> Lab {
        self.to_xyz().to_lab()
    }
}

impl Srgb {
    /// Encoded sRGB to L*a*b*.
    pub fn to_lab(self) -> Lab {
        self.to_linear().to_lab()
    }
}

/// The CIE's cube root with its linear segment near black (CIE 15:2004, 8.2.1).
fn lab_f(t: f64) -> f64 {
    const D: f64 = 6.0 / 29.0;
    if t > D * D * D {
        t.cbrt()
    } else {
        t / (3.0 * D * D) + 4.0 / 29.0
    }
}

fn lab_f_inverse(u: f64) -> f64 {
    const D: f64 = 6.0 / 29.0;
    if u > D {
        u * u * u
    } else {
        3.0 * D * D * (u - 4.0 / 29.0)
    }
}

impl Xyz {
    pub fn to_linear_rgb(self) -> LinearRgb {
        LinearRgb(mul(&XYZ_TO_RGB, self.0))
    }

    pub fn to_lab(self) -> Lab {
        let w = white().0;
        let [fx, fy, fz] = [0, 1, 2].map(|c| lab_f(self.0[c] / w[c]));
        Lab {
            l: 116.0 * fy - 16.0,
            a: 500.0 * (fx - fy),
            b: 200.0 * (fy - fz),
        }
    }
}

impl Lab {
    pub fn to_xyz(self) -> Xyz {
        let w = white().0;
        let fy = (self.l + 16.0) / 116.0;
        let f = [fy + self.a / 500.0, fy, fy - self.b / 200.0];
        Xyz([0, 1, 2].map(|c| w[c] * lab_f_inverse(f[c])))
    }

    pub fn to_linear_rgb(self) -> LinearRgb {
        self.to_xyz().to_linear_rgb()
    }
}

/// CIEDE2000 colour difference between two L*a*b* colours (k_L = k_C = k_H = 1); symmetric.
/// Sharma, Wu and Dalal 2005, equations (1)-(17); angles in degrees as the paper writes them.
pub fn ciede2000(x: Lab, y: Lab) -> f64 {
    let pow7 = |v: f64| v.powi(7);
    let c_mean = 0.5 * (x.a.hypot(x.b) + y.a.hypot(y.b));
    let g = 0.5 * (1.0 - (pow7(c_mean) / (pow7(c_mean) + pow7(25.0))).sqrt());
    // a' (eq. 3), C' (eq. 4), h' in [0, 360) (eq. 5; 0 where a' = b = 0).
    let prime = |p: Lab| {
        let a = (1.0 + g) * p.a;
        let c = a.hypot(p.b);
        let h = if a == 0.0 && p.b == 0.0 {
            0.0
        } else {
            p.b.atan2(a).to_degrees().rem_euclid(360.0)
        };
        (c, h)
    };
    let (c1, h1) = prime(x);
    let (c2, h2) = prime(y);
    let chroma_product = c1 * c2;
    // Delta h' (eq. 10) and the mean hue (eq. 14): both 0-safe for achromatic colours.
    let dh = if chroma_product == 0.0 {
        0.0
    } else {
        let d = h2 - h1;
        if d > 180.0 {
            d - 360.0
        } else if d < -180.0 {
            d + 360.0
        } else {
            d
        }
    };
    let h_mean = if chroma_product == 0.0 {
        h1 + h2
    } else if (h1 - h2).abs() <= 180.0 {
        0.5 * (h1 + h2)
    } else if h1 + h2 < 360.0 {
        0.5 * (h1 + h2 + 360.0)
    } else {
        0.5 * (h1 + h2 - 360.0)
    };
    let d_l = y.l - x.l;
    let d_c = c2 - c1;
    let d_h = 2.0 * chroma_product.sqrt() * (0.5 * dh).to_radians().sin();
    let l_mean = 0.5 * (x.l + y.l);
    let c_mean_prime = 0.5 * (c1 + c2);
    let cos = |deg: f64| deg.to_radians().cos();
    let t =
        1.0 - 0.17 * cos(h_mean - 30.0) + 0.24 * cos(2.0 * h_mean) + 0.32 * cos(3.0 * h_mean + 6.0)
            - 0.20 * cos(4.0 * h_mean - 63.0);
    let d_theta = 30.0 * (-((h_mean - 275.0) / 25.0).powi(2)).exp();
    let r_c = 2.0 * (pow7(c_mean_prime) / (pow7(c_mean_prime) + pow7(25.0))).sqrt();
    let l50 = (l_mean - 50.0).powi(2);
    let s_l = 1.0 + 0.015 * l50 / (20.0 + l50).sqrt();
    let s_c = 1.0 + 0.045 * c_mean_prime;
    let s_h = 1.0 + 0.015 * c_mean_prime * t;
    let r_t = -(2.0 * d_theta).to_radians().sin() * r_c;
    let (l, c, h) = (d_l / s_l, d_c / s_c, d_h / s_h);
    (l * l + c * c + h * h + r_t * c * h).sqrt()
}

fn mul(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    m.map(|row| row[0] * v[0] + row[1] * v[1] + row[2] * v[2])
}

/// The inverse of a non-singular 3x3 matrix (its adjugate over its determinant).
fn invert(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let c = |r: usize, k: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (k1, k2) = ((k + 1) % 3, (k + 2) % 3);
        m[r1][k1] * m[r2][k2] - m[r1][k2] * m[r2][k1]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    [0, 1, 2].map(|r| [0, 1, 2].map(|k| c(k, r) / det))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_matrix_is_the_inverse() {
        let inv = *XYZ_TO_RGB;
        for (r, row) in RGB_TO_XYZ.iter().enumerate() {
            for (k, column) in (0..3).map(|k| (k, inv.map(|inv_row| inv_row[k]))) {
                let p: f64 = row.iter().zip(column).map(|(a, b)| a * b).sum();
                assert!((p - f64::from(u8::from(r == k))).abs() < 1e-12);
            }
        }
    }
}
