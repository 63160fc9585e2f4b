//! Measurements over the methods, run on the GPU by the bake (or by a host on its own
//! models): [`switch`] finds where the hybrid should draw a species as its quad stream
//! instead of its triangles, by comparing both with the supersampled reference.

#![deny(missing_docs)]

pub mod switch;
