//! `render()`: a top view of a [`Scene`] as RGB pixels, drawn with plotters' bitmap backend
//! (fields, TileSwap's tiles by colour, its pivots, the manipulator). No text: the tiles'
//! numbers are shown as colours, so no font is needed.

use numpy::{PyArray1, PyArray3, PyArrayMethods};
use plotters::prelude::*;
use pyo3::prelude::*;
use seads_embodiment::{Environment, Scene, Shape};

use crate::value_error;

/// `env`'s top view as a `size` × `size` × 3 NumPy array; a size outside 16 to 4096 pixels is a
/// `ValueError`.
pub fn image<'py>(
    py: Python<'py>,
    env: &dyn Environment,
    size: usize,
) -> PyResult<Bound<'py, PyArray3<u8>>> {
    frame(py, &env.scene(), size)
}

/// `scene` as a `size` × `size` × 3 NumPy array (see [`image`]).
pub fn frame<'py>(
    py: Python<'py>,
    scene: &Scene,
    size: usize,
) -> PyResult<Bound<'py, PyArray3<u8>>> {
    check_size(size)?;
    let pixels = rgb(scene, size).map_err(value_error)?;
    PyArray1::from_vec(py, pixels).reshape([size, size, 3])
}

/// A `ValueError` for an image size outside 16 to 4096 pixels.
pub fn check_size(size: usize) -> PyResult<()> {
    if !(16..=4096).contains(&size) {
        return Err(value_error(format!(
            "render size {size}: must be 16 to 4096 pixels"
        )));
    }
    Ok(())
}

/// A lit LightsOut field.
const LIT: RGBColor = RGBColor(245, 190, 40);
/// An unlit one.
const UNLIT: RGBColor = RGBColor(70, 70, 80);
/// The table around the board.
const TABLE: RGBColor = RGBColor(235, 235, 230);
/// The manipulator.
const ARM: RGBColor = RGBColor(200, 30, 40);

/// The scene as `size` × `size` RGB pixels, row-major (3 bytes a pixel).
pub fn rgb(scene: &Scene, size: usize) -> Result<Vec<u8>, String> {
    let err = |e: DrawingAreaErrorKind<_>| format!("rendering: {e:?}");
    let mut pixels = vec![0u8; size * size * 3];
    {
        let side = u32::try_from(size).map_err(|e| e.to_string())?;
        let root = BitMapBackend::with_buffer(&mut pixels, (side, side)).into_drawing_area();
        root.fill(&TABLE).map_err(err)?;
        let [u0, v0, u1, v1] = scene.extent;
        // Normalised board coordinates (v downwards) to pixels, the extent filling the image.
        let scale = (size as f64 - 1.0) / (u1 - u0).max(v1 - v0).max(1e-9);
        let px = |u: f64, v: f64| -> (i32, i32) {
            (
                ((u - u0) * scale).round() as i32,
                ((v - v0) * scale).round() as i32,
            )
        };
        let tiles = scene.fields.len().max(1) as f64;
        for field in &scene.fields {
            let colour = match (&field.lit, &field.label) {
                (Some(true), _) => LIT,
                (Some(false), _) => UNLIT,
                (None, Some(label)) => {
                    // TileSwap: each tile its own hue, tile 0 darkest.
                    let tile = label.parse::<f64>().unwrap_or(0.0);
                    let (r, g, b) = HSLColor(tile / tiles, 0.6, 0.35 + 0.3 * tile / tiles).rgb();
                    RGBColor(r, g, b)
                }
                (None, None) => UNLIT,
            };
            // One pixel of table between neighbouring fields.
            let ([a, b, c, d], gap) = (field.rect, (1, 1));
            let (from, to) = (px(a, b), px(c, d));
            let from = (from.0 + gap.0, from.1 + gap.1);
            root.draw(&Rectangle::new([from, to], colour.filled()))
                .map_err(err)?;
        }
        let dot = (size / 60).max(2) as i32;
        for &[u, v] in &scene.pivots {
            root.draw(&Circle::new(px(u, v), dot, WHITE.filled()))
                .map_err(err)?;
        }
        let width = (size / 80).max(1) as u32;
        for shape in &scene.shapes {
            match *shape {
                Shape::Marker { at: [u, v] } => {
                    root.draw(&Circle::new(px(u, v), 2 * dot, ARM.filled()))
                        .map_err(err)?;
                }
                Shape::Segment {
                    from: [a, b],
                    to: [c, d],
                } => {
                    root.draw(&PathElement::new(
                        vec![px(a, b), px(c, d)],
                        ARM.stroke_width(width),
                    ))
                    .map_err(err)?;
                }
                Shape::Joint { at: [u, v] } => {
                    root.draw(&Circle::new(px(u, v), dot + 1, BLACK.filled()))
                        .map_err(err)?;
                }
            }
        }
        root.present().map_err(err)?;
    }
    Ok(pixels)
}
