//! Nothing here: the GPU tests live in `tests/`.
