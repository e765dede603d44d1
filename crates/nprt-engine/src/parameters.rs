//! What every network is to the model file, the optimiser and the checkpoint: a fixed list of
//! named f32 tensors. The names are the model file's contract (`encoder.convs.0.weight`, …,
//! as the weights files written since the first version name them); the order is the one
//! Adam's moments and the GPU kernels' flat buffers follow.
//!
//! A network's gradient is a network of the same shapes, so sums and zeros are defined here
//! once for all of them.

/// What [`Parameters::visit`] calls with each tensor: its name, shape and values.
pub type Visit<'a> = dyn FnMut(&str, &[usize], &[f32]) + 'a;
/// What [`Parameters::visit_mut`] calls with each tensor, its values writable.
pub type VisitMut<'a> = dyn FnMut(&str, &[usize], &mut [f32]) + 'a;

/// A network's tensors, visited in one fixed order.
pub trait Parameters {
    /// Calls `f` with each tensor's name (under `prefix`), shape and values.
    fn visit(&self, prefix: &str, f: &mut Visit);
    /// As [`Self::visit`], in the same order, with the values writable.
    fn visit_mut(&mut self, prefix: &str, f: &mut VisitMut);

    /// Values in all.
    fn num_params(&self) -> usize {
        let mut n = 0;
        self.visit("", &mut |_, _, v| n += v.len());
        n
    }

    /// Every tensor's values, one after the other in visiting order.
    fn flat(&self) -> Vec<f32> {
        let mut all = Vec::with_capacity(self.num_params());
        self.visit("", &mut |_, _, v| all.extend_from_slice(v));
        all
    }

    /// Sets every tensor from `flat` (as [`Self::flat`] lays them out).
    fn set_flat(&mut self, flat: &[f32]) {
        let mut at = 0;
        self.visit_mut("", &mut |_, _, v| {
            v.copy_from_slice(&flat[at..at + v.len()]);
            at += v.len();
        });
        assert_eq!(at, flat.len(), "as many values as the network has");
    }

    /// The same shapes, all zero: a gradient accumulator.
    fn zeros_like(&self) -> Self
    where
        Self: Clone,
    {
        let mut z = self.clone();
        z.visit_mut("", &mut |_, _, v| v.fill(0.0));
        z
    }

    /// Adds `other` (same shapes) to this one, tensor by tensor.
    fn add(&mut self, other: &Self)
    where
        Self: Sized,
    {
        let values = other.flat();
        let mut at = 0;
        self.visit_mut("", &mut |_, _, v| {
            v.iter_mut().zip(&values[at..]).for_each(|(a, b)| *a += b);
            at += v.len();
        });
    }
}

/// `prefix.name`, or `name` at the top.
pub fn child(prefix: &str, name: &str) -> String {
    if prefix.is_empty() {
        name.to_string()
    } else {
        format!("{prefix}.{name}")
    }
}

impl<T: Parameters> Parameters for Vec<T> {
    fn visit(&self, prefix: &str, f: &mut Visit) {
        for (i, item) in self.iter().enumerate() {
            item.visit(&child(prefix, &i.to_string()), f);
        }
    }

    fn visit_mut(&mut self, prefix: &str, f: &mut VisitMut) {
        for (i, item) in self.iter_mut().enumerate() {
            item.visit_mut(&child(prefix, &i.to_string()), f);
        }
    }
}

/// Absent parts (a design without a transfer network) have no tensors; present ones are named
/// as if the option were not there.
impl<T: Parameters> Parameters for Option<T> {
    fn visit(&self, prefix: &str, f: &mut Visit) {
        if let Some(item) = self {
            item.visit(prefix, f);
        }
    }

    fn visit_mut(&mut self, prefix: &str, f: &mut VisitMut) {
        if let Some(item) = self {
            item.visit_mut(prefix, f);
        }
    }
}
