//! Compact, lossless on-disk coding of the node array (`nodes.bin`).
//!
//! Nodes are stored level by level (see [`crate::node`]), so each node's first-child index
//! follows from the child masks of the nodes before it and need not be stored. Each corner
//! depth is stored as its difference (mod 256) from the parent plane's value at that corner,
//! integer-bilinearly interpolated from the parent's corners (128 for roots), which makes most
//! residuals tiny. Layout: magic `FQN2`, node count and root count (u32 little-endian), then a
//! DEFLATE stream of one byte per node (child mask in the low nibble, depth-error code in the
//! high one) followed by all residuals (4 bytes each).

use std::io::{Read, Write};

use crate::node::{MAX_NODES, QuadNode};

const MAGIC: &[u8; 4] = b"FQN2";

/// Predicted corner depths of child `i` from its parent's corners (integer bilinear).
pub fn predict_child(parent: [u8; 4], i: u32) -> [u8; 4] {
    let p = parent.map(u32::from);
    let top = (p[0] + p[1]).div_ceil(2);
    let left = (p[0] + p[2]).div_ceil(2);
    let right = (p[1] + p[3]).div_ceil(2);
    let bottom = (p[2] + p[3]).div_ceil(2);
    let centre = (p[0] + p[1] + p[2] + p[3] + 2) / 4;
    let c = match i {
        0 => [p[0], top, left, centre],
        1 => [top, p[1], centre, right],
        2 => [left, centre, p[2], bottom],
        _ => [centre, right, bottom, p[3]],
    };
    c.map(|x| x as u8)
}

/// For every node, its parent and child slot, `None` for the `roots` first nodes. Checks that
/// the masks describe a level-ordered forest of exactly `nodes.len()` nodes.
fn parents(masks: &[u8], roots: usize) -> Result<Vec<Option<(u32, u32)>>, String> {
    let n = masks.len();
    if roots > n {
        return Err(format!("{roots} roots but only {n} nodes"));
    }
    let mut parent = vec![None; n];
    let mut next = roots as u64;
    for (p, &m) in masks.iter().enumerate() {
        let m = m & 15;
        for i in 0..4u32 {
            if m & (1 << i) != 0 {
                if next >= n as u64 {
                    return Err(format!("node {p} points past the last node ({n})"));
                }
                if next <= p as u64 {
                    return Err(format!("node {p} has a child at {next}, not after itself"));
                }
                parent[next as usize] = Some((p as u32, i));
                next += 1;
            }
        }
    }
    if next != n as u64 {
        return Err(format!(
            "the child masks account for {next} nodes, the file holds {n}"
        ));
    }
    Ok(parent)
}

/// Encode level-ordered nodes whose first `roots` entries are the roots.
pub fn encode(nodes: &[QuadNode], roots: usize) -> Vec<u8> {
    let masks: Vec<u8> = nodes.iter().map(|n| n.mask() | (n.error() << 4)).collect();
    let parent = parents(&masks, roots).expect("encode() is given a valid node forest");
    let mut payload = masks;
    payload.reserve(nodes.len() * 4);
    for (k, node) in nodes.iter().enumerate() {
        let pred = match parent[k] {
            None => [128; 4],
            Some((p, i)) => predict_child(nodes[p as usize].depth, i),
        };
        for (d, p) in node.depth.iter().zip(pred) {
            payload.push(d.wrapping_sub(p));
        }
    }
    let mut out = Vec::with_capacity(payload.len() / 3 + 12);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&(nodes.len() as u32).to_le_bytes());
    out.extend_from_slice(&(roots as u32).to_le_bytes());
    let mut z = flate2::write::DeflateEncoder::new(out, flate2::Compression::best());
    z.write_all(&payload).expect("writing to a Vec cannot fail");
    z.finish().expect("writing to a Vec cannot fail")
}

/// The node and root counts a node file's header claims, checked against the format's
/// limits only: callers compare them with the counts that must agree (the manifest's) before
/// [`decode`] allocates anything.
pub fn header(bytes: &[u8]) -> Result<(usize, usize), String> {
    if bytes.len() < 12 || &bytes[..4] != MAGIC {
        return Err("not a node file of this version (missing the FQN2 header)".into());
    }
    let n = u32::from_le_bytes(bytes[4..8].try_into().unwrap()) as usize;
    let roots = u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize;
    if n as u64 > MAX_NODES {
        return Err(format!("{n} nodes, more than the format's {MAX_NODES}"));
    }
    if roots > n {
        return Err(format!("{roots} roots but only {n} nodes"));
    }
    Ok((n, roots))
}

/// Decode `nodes.bin`; the error says what is wrong.
pub fn decode(bytes: &[u8]) -> Result<(Vec<QuadNode>, usize), String> {
    let (n, roots) = header(bytes)?;
    let mut payload = Vec::new();
    flate2::read::DeflateDecoder::new(&bytes[12..])
        .take(5 * n as u64 + 1)
        .read_to_end(&mut payload)
        .map_err(|e| format!("corrupt compressed data: {e}"))?;
    if payload.len() != 5 * n {
        return Err(format!(
            "decompressed {} bytes, expected {} for {n} nodes",
            payload.len(),
            5 * n
        ));
    }
    let (masks, residuals) = payload.split_at(n);
    let parent = parents(masks, roots)?;
    let mut nodes: Vec<QuadNode> = Vec::with_capacity(n);
    let mut next = roots as u32;
    for k in 0..n {
        let pred = match parent[k] {
            None => [128; 4],
            Some((p, i)) => predict_child(nodes[p as usize].depth, i),
        };
        let depth: [u8; 4] = std::array::from_fn(|c| residuals[4 * k + c].wrapping_add(pred[c]));
        let mask = masks[k] & 15;
        nodes.push(QuadNode::new(mask, next, depth).with_error(masks[k] >> 4));
        next += mask.count_ones();
    }
    Ok((nodes, roots))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_forest() -> Vec<QuadNode> {
        // Two roots; root 0 has children 1 and 3, root 1 has child 0; one grandchild.
        vec![
            QuadNode::new(0b1010, 2, [10, 20, 30, 40]).with_error(15),
            QuadNode::new(0b0001, 4, [200, 200, 200, 200]).with_error(3),
            QuadNode::new(0b0100, 5, [15, 16, 17, 18]),
            QuadNode::new(0, 0, [25, 30, 35, 40]),
            QuadNode::new(0, 0, [199, 201, 198, 202]),
            QuadNode::new(0, 0, [0, 255, 7, 9]),
        ]
    }

    #[test]
    fn round_trip_is_exact() {
        let nodes = sample_forest();
        let bytes = encode(&nodes, 2);
        let (back, roots) = decode(&bytes).unwrap();
        assert_eq!(roots, 2);
        assert_eq!(back, nodes);
    }

    #[test]
    fn prediction_of_a_plane_is_exact_at_even_values() {
        // Plane with corners 0, 100, 40, 140: children on the same plane predict exactly.
        let p = [0, 100, 40, 140];
        assert_eq!(predict_child(p, 0), [0, 50, 20, 70]);
        assert_eq!(predict_child(p, 3), [70, 120, 90, 140]);
    }

    #[test]
    fn corrupt_files_are_rejected_with_a_reason() {
        let bytes = encode(&sample_forest(), 2);
        assert!(decode(&bytes[..8]).unwrap_err().contains("header"));
        let mut wrong_count = bytes.clone();
        wrong_count[4] = 7;
        assert!(decode(&wrong_count).unwrap_err().contains("expected"));
        let mut wrong_roots = bytes.clone();
        wrong_roots[8] = 1;
        assert!(decode(&wrong_roots).is_err());
        let truncated = &bytes[..bytes.len() - 3];
        assert!(decode(truncated).is_err());
    }
}
