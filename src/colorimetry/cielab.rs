//! CIELAB (CIE 15:2004 §8.2.1; ISO/CIE 11664-4) and the CIEDE2000 colour difference (CIE 142-2001;
//! ISO/CIE 11664-6), written after the equations and notes of Sharma, Wu & Dalal, "The CIEDE2000
//! color-difference formula: implementation notes, supplementary test data, and mathematical observations",
//! Color Res. Appl. 30 (2005) 21–30, Eqs. (1)–(21).
//!
//! Errors are propagated by intervals, not by a linearisation: f(t) (the cube root and its linear foot) is
//! monotone, so |f(t ± e) − f(t)| bounds the change of f exactly, and C*ab and hab get the bounds of a point moved
//! by at most (e_a, e_b) in the a*b* plane. An error bound never falls below the change it bounds.
use std::f64::consts::PI;

/// L*, a*, b*.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lab {
    pub l: f64,
    pub a: f64,
    pub b: f64,
}

/// C*ab and hab (degrees in [0, 360); `None` for a neutral colour, C*ab = 0, where the hue is undefined).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Lch {
    pub c: f64,
    pub h: Option<f64>,
}

/// δ = 6/29: the knee of CIELAB's f (CIE 15:2004 Eq. 8.5–8.7, written with δ as in ISO/CIE 11664-4).
const DELTA: f64 = 6.0 / 29.0;

/// CIELAB's f(t): t^(1/3) above δ³, t/(3δ²) + 4/29 below.
pub(crate) fn lab_f(t: f64) -> f64 {
    if t > DELTA * DELTA * DELTA {
        t.cbrt()
    } else {
        t / (3.0 * DELTA * DELTA) + 4.0 / 29.0
    }
}

/// L*, a*, b* of X, Y, Z relative to the white (Xn, Yn, Zn).
pub(crate) fn xyz_to_lab(xyz: [f64; 3], white: [f64; 3]) -> Lab {
    let fx = lab_f(xyz[0] / white[0]);
    let fy = lab_f(xyz[1] / white[1]);
    let fz = lab_f(xyz[2] / white[2]);
    Lab { l: 116.0 * fy - 16.0, a: 500.0 * (fx - fy), b: 200.0 * (fy - fz) }
}

/// Bound on |f(t') − f(t)| for |t' − t| ≤ e (f monotone increasing).
fn f_change(t: f64, e: f64) -> f64 {
    let f = lab_f(t);
    (lab_f(t + e) - f).abs().max((f - lab_f(t - e)).abs())
}

/// Error bounds of L*, a*, b* from absolute error bounds of X, Y, Z.
pub(crate) fn lab_errors(xyz: [f64; 3], err: [f64; 3], white: [f64; 3]) -> [f64; 3] {
    let d: Vec<f64> = (0..3).map(|i| f_change(xyz[i] / white[i], err[i] / white[i])).collect();
    [116.0 * d[1], 500.0 * (d[0] + d[1]), 200.0 * (d[1] + d[2])]
}

/// C*ab and hab.
pub(crate) fn lab_to_lch(lab: Lab) -> Lch {
    let c = lab.a.hypot(lab.b);
    let h = (c > 0.0).then(|| lab.b.atan2(lab.a).to_degrees().rem_euclid(360.0));
    Lch { c, h }
}

/// Error bounds of C*ab and hab (degrees) for a*, b* known to within (ea, eb): the point moves by at most
/// r = hypot(ea, eb), so C changes by at most r and the hue by at most asin(r / C) (180° if r ≥ C).
pub(crate) fn lch_errors(lab: Lab, ea: f64, eb: f64) -> (f64, f64) {
    let r = ea.hypot(eb);
    let c = lab.a.hypot(lab.b);
    let eh = if r < c { (r / c).asin().to_degrees() } else { 180.0 };
    (r, eh)
}

/// CIEDE2000 ΔE00 with the parametric factors kL = kC = kH = 1.
pub fn ciede2000(lab1: Lab, lab2: Lab) -> f64 {
    ciede2000_k(lab1, lab2, [1.0, 1.0, 1.0])
}

/// CIEDE2000 ΔE00 with parametric factors [kL, kC, kH] (Sharma et al. 2005, Eqs. 1–21).
pub(crate) fn ciede2000_k(lab1: Lab, lab2: Lab, k: [f64; 3]) -> f64 {
    let pow7 = |x: f64| x.powi(7);
    let c_ab = 0.5 * (lab1.a.hypot(lab1.b) + lab2.a.hypot(lab2.b)); // Eq. 2–3
    let g = 0.5 * (1.0 - (pow7(c_ab) / (pow7(c_ab) + pow7(25.0))).sqrt()); // Eq. 4
    let a1 = (1.0 + g) * lab1.a; // Eq. 5
    let a2 = (1.0 + g) * lab2.a;
    let c1 = a1.hypot(lab1.b); // Eq. 6
    let c2 = a2.hypot(lab2.b);
    let hue = |b: f64, a: f64| if a == 0.0 && b == 0.0 { 0.0 } else { b.atan2(a).rem_euclid(2.0 * PI) }; // Eq. 7
    let h1 = hue(lab1.b, a1);
    let h2 = hue(lab2.b, a2);
    let dl = lab2.l - lab1.l; // Eq. 8
    let dc = c2 - c1; // Eq. 9
    let neutral = c1 * c2 == 0.0;
    // Eq. 10: Δh' = h2' − h1' brought into [−180°, 180°], computed as the signed angle from (a1', b1') to
    // (a2', b2'), atan2(cross, dot), free of the rounding of the two hue angles. Exactly opposite hues (cross = 0,
    // dot < 0) are the boundary case |h2' − h1'| = 180° of Sharma's rule, which keeps Δh' = h2' − h1' (±180° by
    // which hue angle is larger) and the plain mean hue (h1' + h2')/2 (Eq. 14); they are detected exactly here.
    let (cross, dot) = (a1 * lab2.b - lab1.b * a2, a1 * a2 + lab1.b * lab2.b);
    let opposite = !neutral && cross == 0.0 && dot < 0.0;
    let dh = if neutral {
        0.0
    } else if opposite {
        if h2 >= h1 {
            PI
        } else {
            -PI
        }
    } else {
        cross.atan2(dot)
    };
    let d_big_h = 2.0 * (c1 * c2).sqrt() * (0.5 * dh).sin(); // Eq. 11
    let l_bar = 0.5 * (lab1.l + lab2.l); // Eq. 12
    let c_bar = 0.5 * (c1 + c2); // Eq. 13
                                 // Eq. 14: the mean hue. h1' + Δh'/2 equals Sharma's case analysis modulo 360°, and every use below is periodic.
    let h_bar = if neutral {
        h1 + h2
    } else if opposite {
        0.5 * (h1 + h2)
    } else {
        h1 + 0.5 * dh
    };
    let deg = |x: f64| x.to_radians();
    let t = 1.0 - 0.17 * (h_bar - deg(30.0)).cos() + 0.24 * (2.0 * h_bar).cos() + 0.32 * (3.0 * h_bar + deg(6.0)).cos()
        - 0.20 * (4.0 * h_bar - deg(63.0)).cos(); // Eq. 15
    let h_bar_deg = h_bar.to_degrees().rem_euclid(360.0);
    let d_theta = deg(30.0 * (-((h_bar_deg - 275.0) / 25.0).powi(2)).exp()); // Eq. 16
    let r_c = 2.0 * (pow7(c_bar) / (pow7(c_bar) + pow7(25.0))).sqrt(); // Eq. 17
    let l50 = (l_bar - 50.0).powi(2);
    let s_l = 1.0 + 0.015 * l50 / (20.0 + l50).sqrt(); // Eq. 18
    let s_c = 1.0 + 0.045 * c_bar; // Eq. 19
    let s_h = 1.0 + 0.015 * c_bar * t; // Eq. 20
    let r_t = -(2.0 * d_theta).sin() * r_c; // Eq. 21
    let (x, y, z) = (dl / (k[0] * s_l), dc / (k[1] * s_c), d_big_h / (k[2] * s_h));
    (x * x + y * y + z * z + r_t * y * z).sqrt() // Eq. 22
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lab(l: f64, a: f64, b: f64) -> Lab {
        Lab { l, a, b }
    }

    /// All 34 pairs of Sharma, Wu & Dalal (2005) Table 1, to the 4 decimals published
    /// (`fixtures/reference/ciede2000-sharma2005.json`, with its provenance).
    #[test]
    fn sharma_2005_all_34_pairs() {
        let text = include_str!("../../fixtures/reference/ciede2000-sharma2005.json");
        let v: serde_json::Value = serde_json::from_str(text).unwrap();
        let pairs = v["pairs"].as_array().unwrap();
        assert_eq!(pairs.len(), 34);
        let get = |x: &serde_json::Value| -> Lab {
            let a: Vec<f64> = x.as_array().unwrap().iter().map(|y| y.as_f64().unwrap()).collect();
            lab(a[0], a[1], a[2])
        };
        for (i, p) in pairs.iter().enumerate() {
            let (l1, l2, de) = (get(&p["lab1"]), get(&p["lab2"]), p["de00"].as_f64().unwrap());
            let ours = ciede2000(l1, l2);
            assert!((ours - de).abs() < 1e-4 + 1e-12, "pair {}: {ours} vs published {de}", i + 1);
            // Symmetry (Sharma et al. note ΔE00 is symmetric).
            assert!((ciede2000(l2, l1) - ours).abs() < 1e-12, "pair {} not symmetric", i + 1);
        }
    }

    #[test]
    fn lab_of_white_and_black() {
        let w = [95.047, 100.0, 108.883];
        let l = xyz_to_lab(w, w);
        assert_eq!((l.l, l.a, l.b), (100.0, 0.0, 0.0));
        let k = xyz_to_lab([0.0; 3], w);
        assert!(k.l.abs() < 1e-12 && k.a.abs() < 1e-12 && k.b.abs() < 1e-12);
        // Continuity of f at the knee.
        let t = DELTA.powi(3);
        assert!((t.cbrt() - (t / (3.0 * DELTA * DELTA) + 4.0 / 29.0)).abs() < 1e-15);
        assert_eq!(lab_to_lch(l).h, None);
        let h = lab_to_lch(lab(50.0, 0.0, -3.0)).h.unwrap();
        assert!((h - 270.0).abs() < 1e-12);
    }

    #[test]
    fn error_bounds_cover_actual_changes() {
        let w = [94.811, 100.0, 107.304];
        let xyz = [20.0, 12.0, 0.5];
        let e = [0.3, 0.2, 0.1];
        let b = lab_errors(xyz, e, w);
        let l0 = xyz_to_lab(xyz, w);
        let (ec, eh) = lch_errors(l0, b[1], b[2]);
        let lch0 = lab_to_lch(l0);
        for sx in [-1.0, 0.0, 1.0] {
            for sy in [-1.0, 0.0, 1.0] {
                for sz in [-1.0, 0.0, 1.0] {
                    let l1 = xyz_to_lab([xyz[0] + sx * e[0], xyz[1] + sy * e[1], xyz[2] + sz * e[2]], w);
                    assert!((l1.l - l0.l).abs() <= b[0] * (1.0 + 1e-12));
                    assert!((l1.a - l0.a).abs() <= b[1] * (1.0 + 1e-12));
                    assert!((l1.b - l0.b).abs() <= b[2] * (1.0 + 1e-12));
                    let lch1 = lab_to_lch(l1);
                    assert!((lch1.c - lch0.c).abs() <= ec * (1.0 + 1e-12));
                    let dh = (lch1.h.unwrap() - lch0.h.unwrap() + 180.0).rem_euclid(360.0) - 180.0;
                    assert!(dh.abs() <= eh * (1.0 + 1e-12));
                }
            }
        }
    }
}
