//! NumPy arrays over a run's own storage, without a copy: read-only views whose base object is
//! the result that owns the data, so that the data live as long as any view of them does.

use numpy::ndarray::{ArrayView, Dimension};
use numpy::{Element, PyArray, PyArrayMethods};
use pyo3::prelude::*;

/// A read-only NumPy array over `data`, which `owner` holds.
///
/// The caller's promise: `data` lies in the heap storage of `owner`, a frozen Python object
/// (a `#[pyclass(frozen)]`) whose Rust value is never changed nor moved after it was made.
pub fn lend<'py, T: Element, D: Dimension>(
    owner: &Bound<'py, PyAny>,
    data: ArrayView<'_, T, D>,
) -> PyResult<Bound<'py, PyArray<T, D>>> {
    // SAFETY: the view's memory is a heap buffer of the frozen `owner` (the caller's promise):
    // it is neither reallocated nor freed while `owner` lives, and NumPy keeps `owner` alive
    // (it is the array's base) as long as the array or any view of it lives. The array is made
    // read-only at once, so Python cannot write through it into the owner's data either.
    #[allow(unsafe_code)]
    let array = unsafe { PyArray::borrow_from_array(&data, owner.clone()) };
    array.readwrite().make_nonwriteable();
    Ok(array)
}

/// A NumPy array that owns `data` (moved in, no copy), made read-only like the lent ones.
pub fn owned<'py, T: Element, D: Dimension>(
    py: Python<'py>,
    data: numpy::ndarray::Array<T, D>,
) -> Bound<'py, PyArray<T, D>> {
    use numpy::IntoPyArray;
    let array = data.into_pyarray(py);
    array.readwrite().make_nonwriteable();
    array
}
