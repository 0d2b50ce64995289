//! Caller arrays as slices, checked for NULL and size overflow (never a
//! panic).

use crate::status::{GRANBED_ERR_NULL_POINTER, GRANBED_ERR_SIZE};

/// `count × per` elements of `T`, or `GRANBED_ERR_SIZE` if that many
/// bytes do not fit in `isize`.
pub(crate) fn length<T>(count: usize, per: usize) -> Result<usize, i32> {
    let n = count.checked_mul(per).ok_or(GRANBED_ERR_SIZE)?;
    let bytes = n
        .checked_mul(core::mem::size_of::<T>())
        .ok_or(GRANBED_ERR_SIZE)?;
    if bytes > isize::MAX as usize {
        return Err(GRANBED_ERR_SIZE);
    }
    Ok(n)
}

/// The caller's array `ptr[0..count·per]` (empty for a zero length, where
/// NULL is allowed).
///
/// # Safety
/// Unless the length is zero, `ptr` must point to that many initialised,
/// aligned `T` that nothing writes during the borrow.
pub(crate) unsafe fn input<'a, T>(ptr: *const T, count: usize, per: usize) -> Result<&'a [T], i32> {
    let n = length::<T>(count, per)?;
    if n == 0 {
        return Ok(&[]);
    }
    if ptr.is_null() {
        return Err(GRANBED_ERR_NULL_POINTER);
    }
    // SAFETY: non-NULL, size checked above, validity is the caller's
    // contract.
    Ok(unsafe { core::slice::from_raw_parts(ptr, n) })
}

/// The caller's writable array `ptr[0..count·per]` (see `input`).
///
/// # Safety
/// As `input`, and no other reference may alias it during the borrow.
pub(crate) unsafe fn output<'a, T>(
    ptr: *mut T,
    count: usize,
    per: usize,
) -> Result<&'a mut [T], i32> {
    let n = length::<T>(count, per)?;
    if n == 0 {
        return Ok(&mut []);
    }
    if ptr.is_null() {
        return Err(GRANBED_ERR_NULL_POINTER);
    }
    // SAFETY: as in `input`, plus exclusivity from the caller's contract.
    Ok(unsafe { core::slice::from_raw_parts_mut(ptr, n) })
}

/// An optional writable array: `None` for NULL.
///
/// # Safety
/// As `output` when `ptr` is not NULL.
pub(crate) unsafe fn optional_output<'a, T>(
    ptr: *mut T,
    count: usize,
    per: usize,
) -> Result<Option<&'a mut [T]>, i32> {
    if ptr.is_null() {
        return Ok(None);
    }
    // SAFETY: forwarded contract.
    unsafe { output(ptr, count, per) }.map(Some)
}

/// A required reference to one `T`.
///
/// # Safety
/// `ptr` is NULL or points to an initialised, aligned `T`.
pub(crate) unsafe fn one<'a, T>(ptr: *const T) -> Result<&'a T, i32> {
    // SAFETY: the caller's contract.
    unsafe { ptr.as_ref() }.ok_or(GRANBED_ERR_NULL_POINTER)
}

/// A required writable `T`.
///
/// # Safety
/// `ptr` is NULL or points to an aligned `T` nothing else references.
pub(crate) unsafe fn one_mut<'a, T>(ptr: *mut T) -> Result<&'a mut T, i32> {
    // SAFETY: the caller's contract.
    unsafe { ptr.as_mut() }.ok_or(GRANBED_ERR_NULL_POINTER)
}

/// Collapses a `Result<(), i32>` into a status code.
pub(crate) fn status(r: Result<i32, i32>) -> i32 {
    match r {
        Ok(s) | Err(s) => s,
    }
}
