//! Nothing here: the GPU tests live in `tests/`.

#![deny(missing_docs)]
