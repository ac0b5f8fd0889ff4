//! A top view of an environment as plain data, for rendering and trajectory figures.
//!
//! Coordinates are normalised board coordinates (u to the right, v downwards, the board is the
//! unit square), so every embodiment draws on the same canvas.

use serde::Serialize;

/// One field of the board.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FieldView {
    /// `[u0, v0, u1, v1]`.
    pub rect: [f64; 4],
    /// LightsOut: whether the light is on; `None` for TileSwap.
    pub lit: Option<bool>,
    /// TileSwap: the tile number shown on the field.
    pub label: Option<String>,
    /// Height of the field's top surface above the table, metres (0 where the board is flat;
    /// LightsOut3DJaco raises the fields by their distance from the centre).
    pub height: f64,
}

/// A primitive of the manipulator drawing.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum Shape {
    /// A point marker (the cursor, a fingertip).
    Marker {
        /// Position.
        at: [f64; 2],
    },
    /// A link of an arm.
    Segment {
        /// Start.
        from: [f64; 2],
        /// End.
        to: [f64; 2],
    },
    /// A joint or base.
    Joint {
        /// Centre.
        at: [f64; 2],
    },
}

/// Everything needed to draw a top view.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Scene {
    /// Environment name.
    pub title: String,
    /// The visible area `[u0, v0, u1, v1]` (at least the board; the Reacher's reach is larger).
    pub extent: [f64; 4],
    /// The fields, row-major.
    pub fields: Vec<FieldView>,
    /// TileSwap pivot points (where pushes swap tiles).
    pub pivots: Vec<[f64; 2]>,
    /// The manipulator.
    pub shapes: Vec<Shape>,
}
