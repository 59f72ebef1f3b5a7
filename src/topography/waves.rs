//! Orange-peel wavelength bands of a map's profiles (docs/topography.md §Orange-peel bands): the rms height of
//! the levelled profiles along x (the scan direction of a wave-scan instrument) in each of the bands those
//! instruments report, from each complete row's periodogram.
//!
//! Band rms² = mean over the rows of Σ_{k: L/k in the band} 2|Z_k|²/N² · N/N_valid (Z = DFT of the row less the
//! mean of its valid points, its invalid points at that mean, as the PSD treats them; N points, N_valid of them
//! valid, L = N·Δx its length; Parseval: a complete row's mean square is Σ_k |Z_k|²/N², the factor 2 folds the
//! negative frequencies, the Nyquist bin of an even N counted once). Rows with fewer than half their points
//! valid are left out. A band is read only where the map resolves it: its longest wavelength within the row's
//! length, its shortest at least twice the spacing.
use rustfft::num_complex::Complex64;
use rustfft::FftPlannerScalar;

/// One band: its name and its wavelengths, m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Band {
    pub name: &'static str,
    pub shortest: f64,
    pub longest: f64,
}

/// The bands of the wave-scan instruments, as BYK-Gardner describes them for its wave-scan (the structure
/// spectrum Wa–We, the short and long waves SW and LW, the "dullness" du below 0.1 mm, which a scanning laser
/// reads from scattered light and a height map of its resolution cannot: not listed), mm → m.
pub const BANDS: [Band; 7] = [
    Band { name: "Wa", shortest: 0.1e-3, longest: 0.3e-3 },
    Band { name: "Wb", shortest: 0.3e-3, longest: 1e-3 },
    Band { name: "Wc", shortest: 1e-3, longest: 3e-3 },
    Band { name: "Wd", shortest: 3e-3, longest: 10e-3 },
    Band { name: "We", shortest: 10e-3, longest: 30e-3 },
    Band { name: "SW", shortest: 0.3e-3, longest: 1.2e-3 },
    Band { name: "LW", shortest: 1.2e-3, longest: 12e-3 },
];

/// A band's reading: its rms height (m), or why the map cannot give it.
#[derive(Clone, Debug, PartialEq)]
pub struct BandRms {
    pub band: Band,
    pub rms: Result<f64, String>,
}

/// The band rms heights of the levelled heights `z` (nx × ny, row-major, NaN invalid), `dx` m apart along x.
pub fn band_rms(z: &[f64], nx: usize, ny: usize, dx: f64) -> Vec<BandRms> {
    let length = nx as f64 * dx;
    let rows: Vec<&[f64]> =
        z.chunks(nx).take(ny).filter(|r| 2 * r.iter().filter(|v| v.is_finite()).count() >= nx).collect();
    let power = row_power(&rows, nx);
    BANDS
        .iter()
        .map(|&band| {
            let rms = if rows.is_empty() {
                Err("no row of the map has at least half its points valid".to_string())
            } else if band.longest > length {
                Err(format!(
                    "the map is {:.3} mm long along x; the band needs {:.3} mm",
                    length * 1e3,
                    band.longest * 1e3
                ))
            } else if band.shortest < 2.0 * dx {
                Err(format!(
                    "the spacing along x is {:.2} µm; the band's shortest wavelength needs at most {:.2} µm",
                    dx * 1e6,
                    band.shortest * 0.5e6
                ))
            } else {
                let sum: f64 = (1..=nx / 2)
                    .filter(|&k| {
                        let wavelength = length / k as f64;
                        wavelength >= band.shortest && wavelength < band.longest
                    })
                    .map(|k| power[k])
                    .sum();
                Ok(sum.sqrt())
            };
            BandRms { band, rms }
        })
        .collect()
}

/// The one-sided mean square of bin k (1 ≤ k ≤ n/2) over the rows: mean of 2|Z_k|²/n² · n/n_valid
/// (|Z_k|²/n² at an even n's Nyquist bin), each row less the mean of its valid points, invalid points at it.
fn row_power(rows: &[&[f64]], n: usize) -> Vec<f64> {
    let mut power = vec![0.0; n / 2 + 1];
    if rows.is_empty() {
        return power;
    }
    let fft = FftPlannerScalar::<f64>::new().plan_fft_forward(n);
    let mut buf = vec![Complex64::new(0.0, 0.0); n];
    for row in rows {
        let valid = row.iter().filter(|v| v.is_finite()).count();
        let mean = row.iter().filter(|v| v.is_finite()).sum::<f64>() / valid as f64;
        for (b, &v) in buf.iter_mut().zip(row.iter()) {
            *b = Complex64::new(if v.is_finite() { v - mean } else { 0.0 }, 0.0);
        }
        fft.process(&mut buf);
        let scale = n as f64 / valid as f64;
        for (k, p) in power.iter_mut().enumerate().skip(1) {
            let fold = if 2 * k == n { 1.0 } else { 2.0 };
            *p += fold * buf[k].norm_sqr() / (n * n) as f64 * scale;
        }
    }
    power.iter_mut().for_each(|p| *p /= rows.len() as f64);
    power
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn a_sine_puts_its_rms_in_its_band_alone() {
        // 4 mm of 2 µm points; a 0.2 mm sine of amplitude 1 µm (rms 1/√2 µm) and a 2 mm one of 3 µm.
        let (nx, ny, dx) = (2000, 3, 2e-6);
        let z: Vec<f64> = (0..nx * ny)
            .map(|i| {
                let x = (i % nx) as f64 * dx;
                1e-6 * (2.0 * PI * x / 0.2e-3).sin() + 3e-6 * (2.0 * PI * x / 2e-3).cos()
            })
            .collect();
        let r = band_rms(&z, nx, ny, dx);
        let get = |name: &str| r.iter().find(|b| b.band.name == name).unwrap().rms.clone();
        assert!((get("Wa").unwrap() - 1e-6 / 2f64.sqrt()).abs() < 1e-15, "{:?}", get("Wa"));
        assert!((get("Wc").unwrap() - 3e-6 / 2f64.sqrt()).abs() < 1e-15, "{:?}", get("Wc"));
        assert!(get("Wb").unwrap() < 1e-18 && get("SW").unwrap() < 1e-18);
        // Wd, We and LW need 10, 30 and 12 mm of profile: refused, saying so.
        assert!(get("Wd").unwrap_err().contains("4.000 mm long"));
        assert!(get("We").is_err() && get("LW").unwrap_err().contains("needs 12.000 mm"));
    }

    #[test]
    fn rows_mostly_invalid_are_left_out_and_none_left_is_said() {
        let (nx, dx) = (400, 2e-6);
        let mut z: Vec<f64> = (0..nx * 2).map(|i| 1e-6 * (2.0 * PI * (i % nx) as f64 * dx / 0.2e-3).sin()).collect();
        // The second row loses more than half its points: the first alone is read, exactly.
        z[nx..nx + 201].iter_mut().for_each(|v| *v = f64::NAN);
        let r = band_rms(&z, nx, 2, dx);
        assert!((r[0].rms.clone().unwrap() - 1e-6 / 2f64.sqrt()).abs() < 1e-15);
        // One invalid point in the first row: read with it at the row's mean, within 1 %.
        z[3] = f64::NAN;
        let one = band_rms(&z, nx, 2, dx)[0].rms.clone().unwrap();
        assert!((one / (1e-6 / 2f64.sqrt()) - 1.0).abs() < 0.01, "{one}");
        z[..201].iter_mut().for_each(|v| *v = f64::NAN);
        assert!(band_rms(&z, nx, 2, dx)[0].rms.clone().unwrap_err().contains("no row"));
        // Too coarse for Wa: 60 µm points.
        let coarse = vec![0.0; 100];
        assert!(band_rms(&coarse, 100, 1, 60e-6)[0].rms.clone().unwrap_err().contains("spacing"));
    }
}
