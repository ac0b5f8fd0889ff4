//! Screen calibration (SPEC §7.2): from the four measured screen corners to a map from
//! normalised screen coordinates (x, y) ∈ [0,1]² and height z ∈ [0,1] to arm coordinates (mm).
//!
//! 1. Fit a plane to the corners by least squares: centroid c, normal n = right singular vector
//!    of the smallest singular value of the centred corners, oriented towards the arm.
//! 2. Project the corners onto the plane and express them in an orthonormal basis (e1, e2).
//! 3. Fit the perspective transform H from the normalised corners (0,0), (1,0), (1,1), (0,1) —
//!    origin top-left as for the Cursor — to the projected corners (direct linear transform).
//! 4. Map: (u, v) = H(x, y); X = c + u·e1 + v·e2 + n·z·d_max (z = 1 ≈ 10 cm above the screen).

use std::path::Path;

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use crate::UarmError;

/// How far from its base (mm, on each axis) any point of a calibration may lie: the uArm Swift
/// Pro reaches about 320 mm, so a corner or height beyond this is a unit or typing error.
pub const REACH_MM: f64 = 1000.0;

/// The measured corners and the height scale; everything else is derived (and validated) on load.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrationFile {
    /// Arm positions (mm) of the screen corners, in the order top-left (0,0), top-right (1,0),
    /// bottom-right (1,1), bottom-left (0,1) of the usable screen area.
    pub corners: [[f64; 3]; 4],
    /// Distance from the screen for z = 1, mm.
    pub d_max_mm: f64,
}

/// A validated calibration.
#[derive(Debug, Clone, PartialEq)]
pub struct Calibration {
    file: CalibrationFile,
    centroid: Vector3<f64>,
    normal: Vector3<f64>,
    e1: Vector3<f64>,
    e2: Vector3<f64>,
    homography: Matrix3<f64>,
    /// Largest distance of a measured corner from the fitted plane, mm.
    pub plane_residual_mm: f64,
}

/// Corners closer than this (mm) count as repeated.
const MIN_CORNER_DISTANCE_MM: f64 = 5.0;

impl Calibration {
    /// Fits a calibration to measured corners; errors for degenerate corner sets (repeated,
    /// collinear, or not forming a convex quadrilateral in the right order).
    pub fn fit(file: CalibrationFile) -> Result<Self, UarmError> {
        let bad = |m: String| UarmError::Calibration(m);
        if file.d_max_mm.is_nan() || file.d_max_mm <= 0.0 || file.d_max_mm > REACH_MM {
            return Err(bad(format!(
                "d_max_mm must be positive and within the arm's reach ({REACH_MM} mm), got {}",
                file.d_max_mm
            )));
        }
        if let Some(far) = file
            .corners
            .iter()
            .find(|c| c.iter().any(|v| v.is_nan() || v.abs() > REACH_MM))
        {
            return Err(bad(format!(
                "corner {far:?} lies beyond the arm's reach ({REACH_MM} mm from its base on each \
                 axis): were the corners recorded in another unit?"
            )));
        }
        let p: Vec<Vector3<f64>> = file
            .corners
            .iter()
            .map(|c| Vector3::new(c[0], c[1], c[2]))
            .collect();
        if p.iter().any(|v| !v.iter().all(|x| x.is_finite())) {
            return Err(bad("corner coordinates must be finite numbers".into()));
        }
        for i in 0..4 {
            for j in i + 1..4 {
                if (p[i] - p[j]).norm() < MIN_CORNER_DISTANCE_MM {
                    return Err(bad(format!(
                        "corners {i} and {j} are {:.1} mm apart: a corner was recorded twice",
                        (p[i] - p[j]).norm()
                    )));
                }
            }
        }
        let centroid = p.iter().sum::<Vector3<f64>>() / 4.0;
        let centred = DMatrix::from_fn(4, 3, |r, c| p[r][c] - centroid[c]);
        let svd = centred.svd(false, true);
        let v_t = svd.v_t.expect("requested");
        let mut order: Vec<usize> = (0..3).collect();
        order.sort_by(|&a, &b| svd.singular_values[b].total_cmp(&svd.singular_values[a]));
        let (s_max, s_mid) = (svd.singular_values[order[0]], svd.singular_values[order[1]]);
        if s_mid < 0.05 * s_max {
            return Err(bad("the corners lie on a line: they span no screen".into()));
        }
        let row = v_t.row(order[2]);
        let mut normal = Vector3::new(row[0], row[1], row[2]).normalize();
        // Towards the arm: up, unless the screen stands upright; then towards the arm's base.
        let towards = if normal.z.abs() > 0.3 {
            Vector3::z()
        } else {
            -centroid
        };
        if normal.dot(&towards) < 0.0 {
            normal = -normal;
        }
        let project = |v: &Vector3<f64>| v - normal * (v - centroid).dot(&normal);
        let projected: Vec<Vector3<f64>> = p.iter().map(project).collect();
        let e1 = (projected[1] - projected[0]).normalize();
        let e2 = normal.cross(&e1);
        let uv: Vec<[f64; 2]> = projected
            .iter()
            .map(|q| [(q - centroid).dot(&e1), (q - centroid).dot(&e2)])
            .collect();
        check_convex(&uv).map_err(bad)?;
        let homography = fit_homography(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], &uv)
            .ok_or_else(|| bad("the corners admit no perspective transform".into()))?;
        let plane_residual_mm = p
            .iter()
            .map(|v| (v - centroid).dot(&normal).abs())
            .fold(0.0, f64::max);
        Ok(Self {
            file,
            centroid,
            normal,
            e1,
            e2,
            homography,
            plane_residual_mm,
        })
    }

    /// The measured corners and height scale.
    pub fn file(&self) -> &CalibrationFile {
        &self.file
    }

    /// Unit normal of the screen, pointing towards the arm.
    pub fn normal(&self) -> [f64; 3] {
        [self.normal.x, self.normal.y, self.normal.z]
    }

    /// Arm coordinates (mm) of normalised screen point (x, y) at height z (clamped to `[0, 1]³`).
    pub fn to_arm(&self, x: f64, y: f64, z: f64) -> [f64; 3] {
        let (x, y, z) = (x.clamp(0.0, 1.0), y.clamp(0.0, 1.0), z.clamp(0.0, 1.0));
        let h = self.homography * Vector3::new(x, y, 1.0);
        let (u, v) = (h.x / h.z, h.y / h.z);
        let p = self.centroid + self.e1 * u + self.e2 * v + self.normal * (z * self.file.d_max_mm);
        [p.x, p.y, p.z]
    }

    /// Normalised screen coordinates (x, y, z) of an arm position (the inverse of [`to_arm`],
    /// not clamped).
    ///
    /// [`to_arm`]: Calibration::to_arm
    pub fn to_screen(&self, p: [f64; 3]) -> [f64; 3] {
        let d = Vector3::new(p[0], p[1], p[2]) - self.centroid;
        let (u, v, h) = (d.dot(&self.e1), d.dot(&self.e2), d.dot(&self.normal));
        let inv = self
            .homography
            .try_inverse()
            .expect("fitted homographies are invertible");
        let s = inv * Vector3::new(u, v, 1.0);
        [s.x / s.z, s.y / s.z, h / self.file.d_max_mm]
    }

    /// Reads and validates a calibration TOML file.
    pub fn load(path: &Path) -> Result<Self, UarmError> {
        let text = std::fs::read_to_string(path).map_err(|e| UarmError::Io {
            what: path.display().to_string(),
            source: Box::new(e),
        })?;
        let file: CalibrationFile = toml::from_str(&text)
            .map_err(|e| UarmError::Calibration(format!("{}: {}", path.display(), e.message())))?;
        Self::fit(file)
    }

    /// Writes the calibration as TOML (atomically and durably: temporary file, fsync, rename).
    pub fn save(&self, path: &Path) -> Result<(), UarmError> {
        let text = format!(
            "# uArm screen calibration (seads uarm calibrate). Corners: TL, TR, BR, BL in mm.\n{}",
            toml::to_string(&self.file).expect("serialises")
        );
        write_atomic(path, &text)
    }
}

/// Writes `text` to `path` atomically and durably (temporary file, fsync, rename): the uArm's
/// settings files are never half-written.
pub(crate) fn write_atomic(path: &Path, text: &str) -> Result<(), UarmError> {
    let io = |e: std::io::Error| UarmError::Io {
        what: format!("writing {}", path.display()),
        source: Box::new(e),
    };
    let mut file = atomic_write_file::AtomicWriteFile::open(path).map_err(io)?;
    std::io::Write::write_all(&mut file, text.as_bytes()).map_err(io)?;
    file.commit().map_err(io)
}

/// The quadrilateral (in order) must be convex and wind consistently, with a real area.
fn check_convex(q: &[[f64; 2]]) -> Result<(), String> {
    let cross = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
        (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0])
    };
    let turns: Vec<f64> = (0..4)
        .map(|i| cross(q[i], q[(i + 1) % 4], q[(i + 2) % 4]))
        .collect();
    let area = 0.5
        * (0..4)
            .map(|i| q[i][0] * q[(i + 1) % 4][1] - q[(i + 1) % 4][0] * q[i][1])
            .sum::<f64>()
            .abs();
    if !(turns.iter().all(|&t| t > 0.0) || turns.iter().all(|&t| t < 0.0)) {
        return Err("the corners do not form a convex quadrilateral in the order top-left, top-right, bottom-right, bottom-left".into());
    }
    if area < MIN_CORNER_DISTANCE_MM * MIN_CORNER_DISTANCE_MM {
        return Err("the corners enclose no area: they are (nearly) collinear".into());
    }
    Ok(())
}

/// The perspective transform mapping `from[i]` to `to[i]` (four point pairs, h33 = 1).
fn fit_homography(from: &[[f64; 2]; 4], to: &[[f64; 2]]) -> Option<Matrix3<f64>> {
    let mut a = DMatrix::<f64>::zeros(8, 8);
    let mut b = DVector::<f64>::zeros(8);
    for i in 0..4 {
        let ([x, y], [u, v]) = (from[i], to[i]);
        let r = 2 * i;
        a.row_mut(r)
            .copy_from_slice(&[x, y, 1.0, 0.0, 0.0, 0.0, -u * x, -u * y]);
        a.row_mut(r + 1)
            .copy_from_slice(&[0.0, 0.0, 0.0, x, y, 1.0, -v * x, -v * y]);
        b[r] = u;
        b[r + 1] = v;
    }
    let h = a.lu().solve(&b)?;
    let m = Matrix3::new(h[0], h[1], h[2], h[3], h[4], h[5], h[6], h[7], 1.0);
    m.iter().all(|v| v.is_finite()).then_some(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rectangular screen of `w`×`h` mm, rotated by `yaw` about Z and tilted by `tilt` about
    /// its top edge, with its top-left corner at `origin`.
    fn screen(origin: [f64; 3], w: f64, h: f64, yaw: f64, tilt: f64) -> [[f64; 3]; 4] {
        let right = Vector3::new(yaw.cos(), yaw.sin(), 0.0);
        let down =
            Vector3::new(-yaw.sin(), yaw.cos(), 0.0) * tilt.cos() + Vector3::z() * -tilt.sin();
        let o = Vector3::new(origin[0], origin[1], origin[2]);
        let c = |x: f64, y: f64| {
            let p = o + right * (x * w) + down * (y * h);
            [p.x, p.y, p.z]
        };
        [c(0.0, 0.0), c(1.0, 0.0), c(1.0, 1.0), c(0.0, 1.0)]
    }

    fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
        a.iter().zip(&b).all(|(x, y)| (x - y).abs() < tol)
    }

    #[test]
    fn tilted_screens_map_corners_centre_and_height() {
        for (yaw, tilt) in [(0.0, 0.0), (0.3, 0.1), (-1.2, 0.25), (2.5, -0.2)] {
            let corners = screen([180.0, -60.0, 20.0], 217.0, 135.0, yaw, tilt);
            let cal = Calibration::fit(CalibrationFile {
                corners,
                d_max_mm: 100.0,
            })
            .unwrap();
            for (i, &(x, y)) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
                .iter()
                .enumerate()
            {
                assert!(
                    close(cal.to_arm(x, y, 0.0), corners[i], 1e-6),
                    "yaw {yaw} tilt {tilt} corner {i}"
                );
            }
            // A rectangle: the centre maps to the mean of the corners.
            let centre = [0, 1, 2].map(|k| corners.iter().map(|c| c[k]).sum::<f64>() / 4.0);
            assert!(close(cal.to_arm(0.5, 0.5, 0.0), centre, 1e-6));
            // z = 1 is d_max above the screen along its normal, which points up (towards the arm).
            let up = cal.to_arm(0.5, 0.5, 1.0);
            let n = cal.normal();
            assert!(close(up, [0, 1, 2].map(|k| centre[k] + 100.0 * n[k]), 1e-6));
            assert!(n[2] > 0.0);
            let back = cal.to_screen(cal.to_arm(0.3, 0.8, 0.25));
            assert!(close(back, [0.3, 0.8, 0.25], 1e-9));
        }
    }

    #[test]
    fn noisy_corners_fit_within_the_noise() {
        let mut corners = screen([200.0, 50.0, 10.0], 200.0, 120.0, 0.4, 0.15);
        let noise = [
            [0.4, -0.3, 0.5],
            [-0.2, 0.4, -0.6],
            [0.3, 0.1, 0.4],
            [-0.5, -0.2, -0.3],
        ];
        for (c, n) in corners.iter_mut().zip(noise) {
            for k in 0..3 {
                c[k] += n[k];
            }
        }
        let cal = Calibration::fit(CalibrationFile {
            corners,
            d_max_mm: 100.0,
        })
        .unwrap();
        assert!(cal.plane_residual_mm < 1.0, "{}", cal.plane_residual_mm);
        for (i, &(x, y)) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
            .iter()
            .enumerate()
        {
            assert!(close(cal.to_arm(x, y, 0.0), corners[i], 1.0), "corner {i}");
        }
    }

    #[test]
    fn degenerate_corners_are_rejected() {
        let good = screen([180.0, -60.0, 20.0], 217.0, 135.0, 0.2, 0.1);
        let mut repeated = good;
        repeated[2] = repeated[1];
        let collinear = [
            [0.0, 0.0, 0.0],
            [100.0, 0.0, 0.0],
            [200.0, 0.0, 0.0],
            [300.0, 0.0, 0.0],
        ];
        let crossed = [good[0], good[2], good[1], good[3]];
        for (corners, needle) in [
            (repeated, "recorded twice"),
            (collinear, "line"),
            (crossed, "convex"),
        ] {
            let err = Calibration::fit(CalibrationFile {
                corners,
                d_max_mm: 100.0,
            })
            .unwrap_err()
            .to_string();
            assert!(err.contains(needle), "{needle}: {err}");
        }
        assert!(matches!(
            Calibration::fit(CalibrationFile {
                corners: good,
                d_max_mm: 0.0
            }),
            Err(UarmError::Calibration(_))
        ));
        // Absurd sizes (issue 32): a height scale of 1e300 mm, corners metres from the arm.
        let err = Calibration::fit(CalibrationFile {
            corners: good,
            d_max_mm: 1e300,
        })
        .unwrap_err()
        .to_string();
        assert!(err.contains("reach"), "{err}");
        let far = good.map(|c| c.map(|v| v * 20.0));
        let err = Calibration::fit(CalibrationFile {
            corners: far,
            d_max_mm: 100.0,
        })
        .unwrap_err()
        .to_string();
        assert!(err.contains("beyond the arm's reach"), "{err}");
        let mut nan = good;
        nan[0][1] = f64::NAN;
        assert!(matches!(
            Calibration::fit(CalibrationFile {
                corners: nan,
                d_max_mm: 100.0
            }),
            Err(UarmError::Calibration(_))
        ));
    }

    #[test]
    fn files_round_trip() {
        let dir = std::env::temp_dir().join(format!("seads-cal-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let cal = Calibration::fit(CalibrationFile {
            corners: screen([180.0, -60.0, 20.0], 217.0, 135.0, 0.0, 0.0),
            d_max_mm: 95.0,
        })
        .unwrap();
        let path = dir.join("cal.toml");
        cal.save(&path).unwrap();
        assert_eq!(Calibration::load(&path).unwrap(), cal);
        std::fs::write(&path, "corners = 3\n").unwrap();
        assert!(matches!(
            Calibration::load(&path),
            Err(UarmError::Calibration(_))
        ));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
