//! Multilayer perceptrons as the checkpoints store them: linear layers (weight `out × in`, bias
//! `out`) with ReLU between, evaluated with `ndarray`'s matrix products.

use ndarray::{Array1, Array2, ArrayView2, Axis};

use crate::InferError;

/// One linear layer: y = x Wᵀ + b.
#[derive(Debug, Clone)]
pub struct Dense {
    /// `out × in`.
    pub weight: Array2<f32>,
    /// `out`.
    pub bias: Array1<f32>,
}

impl Dense {
    /// Checks that the shapes fit each other.
    pub fn new(weight: Array2<f32>, bias: Array1<f32>, name: &str) -> Result<Self, InferError> {
        if weight.nrows() != bias.len() || weight.is_empty() {
            return Err(InferError::Shape(format!(
                "{name}: a weight of {:?} and a bias of {}",
                weight.shape(),
                bias.len()
            )));
        }
        Ok(Self { weight, bias })
    }

    /// Inputs per row.
    pub fn inputs(&self) -> usize {
        self.weight.ncols()
    }

    /// Outputs per row.
    pub fn outputs(&self) -> usize {
        self.weight.nrows()
    }

    /// `x` (rows × inputs) through the layer.
    pub fn forward(&self, x: ArrayView2<f32>) -> Array2<f32> {
        let mut y = x.dot(&self.weight.t());
        y += &self.bias.view().insert_axis(Axis(0));
        y
    }
}

/// Layers with ReLU between them (none after the last).
#[derive(Debug, Clone)]
pub struct Mlp {
    layers: Vec<Dense>,
}

impl Mlp {
    /// Layers in order; each one's inputs must be the previous one's outputs.
    pub fn new(layers: Vec<Dense>, name: &str) -> Result<Self, InferError> {
        if layers.is_empty() {
            return Err(InferError::Shape(format!("{name}: no layer")));
        }
        for (i, pair) in layers.windows(2).enumerate() {
            if pair[0].outputs() != pair[1].inputs() {
                return Err(InferError::Shape(format!(
                    "{name}: layer {i} gives {} values, layer {} takes {}",
                    pair[0].outputs(),
                    i + 1,
                    pair[1].inputs()
                )));
            }
        }
        Ok(Self { layers })
    }

    /// Inputs per row.
    pub fn inputs(&self) -> usize {
        self.layers[0].inputs()
    }

    /// Outputs per row.
    pub fn outputs(&self) -> usize {
        self.layers.last().expect("one layer at least").outputs()
    }

    /// The layers.
    pub fn layers(&self) -> &[Dense] {
        &self.layers
    }

    /// The last hidden layer's activations (after its ReLU); `x` itself for one layer.
    pub fn features(&self, x: ArrayView2<f32>) -> Array2<f32> {
        let mut h = x.to_owned();
        for layer in &self.layers[..self.layers.len() - 1] {
            h = layer.forward(h.view());
            h.mapv_inplace(|v| v.max(0.0));
        }
        h
    }

    /// The output layer.
    pub fn head(&self) -> &Dense {
        self.layers.last().expect("one layer at least")
    }

    /// `x` (rows × inputs) through every layer.
    pub fn forward(&self, x: ArrayView2<f32>) -> Array2<f32> {
        self.head().forward(self.features(x).view())
    }
}
