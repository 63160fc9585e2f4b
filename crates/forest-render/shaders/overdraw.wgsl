// The overdraw view: a heat map of the fragment invocations counted at each pixel
// (forest_render::fragments, counter 0 of COUNT_STRIDE), in bands of powers of two, with a
// legend of the bands along the bottom-left edge. Mirrored by
// forest_render::passes::overdraw::{band, OVERDRAW_COLOURS}.

struct OverdrawParams {
    width: u32,
    height: u32,
    // Side of a legend swatch in pixels (0: no legend).
    legend: u32,
    _pad: u32,
}

@group(0) @binding(0) var<storage, read> counts: array<u32>;
@group(0) @binding(1) var<uniform> params: OverdrawParams;

const COUNT_STRIDE: u32 = 7u;
const BANDS: u32 = 9u;
// The narrowest swatch that holds its label.
const LABELLED_SIDE: u32 = 14u;

// Linear RGB of band 0 (no fragment), 1 (one), 2 (2–3), 3 (4–7), … 8 (128 or more).
const OVERDRAW_COLOURS = array<vec3<f32>, 9>(
    vec3<f32>(0.0, 0.0, 0.0),
    vec3<f32>(0.02, 0.05, 0.6),
    vec3<f32>(0.0, 0.4, 0.75),
    vec3<f32>(0.02, 0.55, 0.05),
    vec3<f32>(0.8, 0.72, 0.02),
    vec3<f32>(0.87, 0.22, 0.01),
    vec3<f32>(0.72, 0.01, 0.01),
    vec3<f32>(0.8, 0.05, 0.8),
    vec3<f32>(1.0, 1.0, 1.0),
);

// The band of `n` fragments: 0 for none, else 1 + floor(log2 n), at most BANDS − 1.
fn band(n: u32) -> u32 {
    if (n == 0u) { return 0u; }
    return min(firstLeadingBit(n) + 1u, BANDS - 1u);
}

// 3×5 digit glyphs, bit (4 − row) · 3 + (2 − column) set where the digit is drawn.
const DIGITS = array<u32, 10>(
    0x7b6fu, 0x2c97u, 0x73e7u, 0x73cfu, 0x5bc9u, 0x79cfu, 0x79efu, 0x7249u, 0x7befu, 0x7bcfu,
);

// Whether pixel (x, y) of a label cell (origin top-left, glyph pixels `scale` wide) shows a
// stroke of the band's lower bound (1, 2, 4 … 128; 0 for band 0).
fn label_ink(b: u32, x: u32, y: u32, scale: u32) -> bool {
    let value = select(0u, 1u << (b - 1u), b > 0u);
    var digits = array<u32, 3>(0u, 0u, 0u);
    var count = 0u;
    var v = value;
    loop {
        digits[count] = v % 10u;
        count += 1u;
        v /= 10u;
        if (v == 0u || count == 3u) { break; }
    }
    let gx = x / scale;
    let gy = y / scale;
    // Each glyph 3 wide and a column of space.
    let k = gx / 4u;
    let col = gx % 4u;
    if (k >= count || col == 3u || gy >= 5u) { return false; }
    let d = digits[count - 1u - k];
    return ((DIGITS[d] >> ((4u - gy) * 3u + (2u - col))) & 1u) == 1u;
}

@vertex
fn vs_overdraw(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let x = f32(i & 1u) * 4.0 - 1.0;
    let y = f32(i >> 1u) * 4.0 - 1.0;
    return vec4<f32>(x, y, 0.0, 1.0);
}

@fragment
fn fs_overdraw(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let x = min(u32(pos.x), params.width - 1u);
    let y = min(u32(pos.y), params.height - 1u);
    let s = params.legend;
    // The legend: one swatch per band along the bottom, the band's lower bound under it in
    // black on grey ("or more" is implied for the last).
    if (s > 0u && y + 2u * s >= params.height && x < BANDS * s) {
        let b = x / s;
        let c = OVERDRAW_COLOURS[b];
        let ly = y + 2u * s - params.height;
        // The widest label, "128", is 11 glyph pixels wide: it fits in a cell.
        let scale = max((s - 2u) / 12u, 1u);
        let margin = scale;
        var ink = false;
        if (s >= LABELLED_SIDE && ly >= s + margin && x % s >= margin) {
            ink = label_ink(b, x % s - margin, ly - s - margin, scale);
        }
        let label = vec3<f32>(0.0);
        let back = select(c, vec3<f32>(0.5), ly >= s);
        // A dark column between the cells.
        let gap = x % s == s - 1u;
        return vec4<f32>(select(select(back, label, ink), vec3<f32>(0.02), gap), 1.0);
    }
    let n = counts[(y * params.width + x) * COUNT_STRIDE];
    return vec4<f32>(OVERDRAW_COLOURS[band(n)], 1.0);
}
