//! Cross-crate validation suites of granbed; the suites are in `tests/`.
