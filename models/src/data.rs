//! Data of a scene (loads, obstacles, boundary values, exact solutions) as functions of
//! the point: plain functions for the built-in scenes, shared closures for scenes read
//! from files (expressions compiled once).

use fem_runtime::DataFn;
use std::fmt;
use std::sync::Arc;

/// A shared function of the point with values of type `T`.
pub type SharedFn<T> = Arc<dyn Fn(&[f64]) -> T + Send + Sync>;

/// A function of the point `x` (`[x]` on intervals, `[x, y]` on triangles) with values
/// of type `T`: a plain function (so built-in scenes stay `const`) or a shared closure.
pub enum Data<T: 'static = f64> {
    /// A plain function.
    Fn(fn(&[f64]) -> T),
    /// A closure, e.g. a compiled expression of a scene file.
    Shared(SharedFn<T>),
}

impl<T> Data<T> {
    /// The value at `x`.
    #[inline]
    pub fn at(&self, x: &[f64]) -> T {
        match self {
            Data::Fn(f) => f(x),
            Data::Shared(f) => f(x),
        }
    }

    /// A closure as data.
    pub fn shared(f: impl Fn(&[f64]) -> T + Send + Sync + 'static) -> Self {
        Data::Shared(Arc::new(f))
    }
}

impl<T> Data<T> {
    /// The function as a trait object.
    pub fn as_fn(&self) -> &(dyn Fn(&[f64]) -> T + Sync + 'static) {
        match self {
            Data::Fn(f) => f,
            Data::Shared(f) => &**f,
        }
    }
}

impl Data<f64> {
    /// The function as the runtime's data type (what `Coefficients` take).
    pub fn as_data_fn(&self) -> &DataFn {
        match self {
            Data::Fn(f) => f,
            Data::Shared(f) => &**f,
        }
    }
}

impl<T> Clone for Data<T> {
    fn clone(&self) -> Self {
        match self {
            Data::Fn(f) => Data::Fn(*f),
            Data::Shared(f) => Data::Shared(Arc::clone(f)),
        }
    }
}

impl<T> fmt::Debug for Data<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Data::Fn(_) => f.write_str("Data::Fn(..)"),
            Data::Shared(_) => f.write_str("Data::Shared(..)"),
        }
    }
}

impl<T> From<fn(&[f64]) -> T> for Data<T> {
    fn from(f: fn(&[f64]) -> T) -> Self {
        Data::Fn(f)
    }
}
