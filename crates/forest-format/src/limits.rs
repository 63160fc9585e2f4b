//! World limits every file kind shares.

/// Largest coordinate of a tree (metres from the origin on any axis): far enough for any
/// forest, near enough that far planes and camera matrices stay finite in single precision.
pub const MAX_COORDINATE: f32 = 1.0e7;
