//! Every tree its own colour: a per-instance shift of the leaves' hue, saturation and
//! brightness (and a smaller one of the bark's brightness), and the turn of the seasons.
//! One model, evaluated alike by every method on the GPU (`tint.wgsl` in forest-render,
//! operation for operation) and here on the CPU ([`tree_albedo`]).
//!
//! Nothing is uploaded per frame and nothing is stored per tree: each tree's numbers come from
//! a hash of its instance index ([`randoms`]), or of the explicit value a forest file may give
//! it ([`explicit_code`]). The amplitudes are per species ([`SpeciesColour`]), scaled by the
//! forest's `amount` ([`Colouring`]). The season is a frame parameter in the camera uniform
//! (0 spring, ⅓ summer, ⅔ autumn, 1 late autumn; [`parse_season`]); each tree is ahead or
//! behind by up to [`SEASON_SPREAD`] × amount, so a forest turns tree by tree.
//!
//! Leaves are told from wood by the translucency every form already stores (the models'
//! material `Kd.a`, the atlases' surface alpha): `leafness = τ / LEAF_TRANSLUCENCY`, so a
//! coarse texel that mixes both takes each shift in its share. On an albedo `a` (linear RGB,
//! not premultiplied) with the tree's numbers `r ∈ [−1, 1]`:
//!
//! ```text
//! leaf = value(saturation(hue(a, r₀·hue), r₁·saturation), r₂·brightness)   then the season
//! bark = a · (1 + r₂·bark)
//! out  = clamp(mix(bark, leaf, leafness), 0, 1)
//! ```
//!
//! The hue turns about the grey axis (a rotation of RGB space, which keeps the grey level of
//! greys); the saturation scales the distance from the albedo's luminance; the season mixes
//! the leaf towards its key's tint times the leaf's own luminance, so a texture keeps its
//! detail. With no colouring and no season ([`TreeColour::NONE`], season < 0) the albedo is
//! returned unchanged, bit for bit.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::shading::LEAF_TRANSLUCENCY;

/// Relative luminance weights of linear RGB (Rec. 709).
pub const LUMA: [f32; 3] = [0.2126, 0.7152, 0.0722];
/// How far ahead or behind the forest's season a tree may be, at amount 1 (a fraction of the
/// year's ramp, from spring to late autumn).
pub const SEASON_SPREAD: f32 = 0.12;
/// The largest `amount` a forest may give (3 times the natural amplitudes).
pub const MAX_AMOUNT: f32 = 3.0;
/// Names that mark a species as evergreen ([`SpeciesColour::by_name`]).
pub const EVERGREEN_NAMES: [&str; 7] = [
    "pine", "spruce", "fir", "cedar", "cypress", "juniper", "yew",
];
/// The seasons' names and where they lie on the ramp.
pub const SEASONS: [(&str, f32); 4] = [
    ("spring", 0.0),
    ("summer", 1.0 / 3.0),
    ("autumn", 2.0 / 3.0),
    ("late-autumn", 1.0),
];

/// A key of the seasons' ramp: the leaves' tint at that season (linear RGB, relative to the
/// leaf's own luminance: the leaf becomes `tint · luminance(leaf)`) and how strongly it
/// replaces the model's colour (0: not at all, 1: wholly).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeasonKey {
    /// Linear RGB multiplier of the leaf's luminance, each 0 to 8.
    pub tint: [f32; 3],
    /// Strength, 0 to 1.
    pub strength: f32,
}

/// How a species' trees vary, and how its leaves turn through the seasons.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpeciesColour {
    /// Largest turn of the leaves' hue (degrees, about RGB's grey axis), 0 to 60.
    pub hue_deg: f32,
    /// Largest relative change of the leaves' saturation, 0 to 1.
    pub saturation: f32,
    /// Largest relative change of the leaves' brightness, 0 to 1.
    pub brightness: f32,
    /// Largest relative change of the bark's brightness, 0 to 1.
    pub bark: f32,
    /// The leaves in spring (summer is the model's own colour).
    pub spring: SeasonKey,
    /// The leaves in autumn.
    pub autumn: SeasonKey,
    /// The leaves in late autumn.
    pub late_autumn: SeasonKey,
}

impl SpeciesColour {
    /// A broadleaf that turns: yellow-green in spring, orange in autumn, rust brown late.
    pub const DECIDUOUS: SpeciesColour = SpeciesColour {
        hue_deg: 9.0,
        saturation: 0.18,
        brightness: 0.16,
        bark: 0.08,
        spring: SeasonKey {
            tint: [0.83, 1.42, 0.125],
            strength: 0.45,
        },
        autumn: SeasonKey {
            tint: [4.0, 1.0, 0.1],
            strength: 0.85,
        },
        late_autumn: SeasonKey {
            tint: [2.6, 0.45, 0.13],
            strength: 0.9,
        },
    };

    /// A conifer: less variation, and its needles barely change (an eighth of
    /// [`SpeciesColour::DECIDUOUS`]'s season strengths).
    pub const EVERGREEN: SpeciesColour = SpeciesColour {
        hue_deg: 6.0,
        saturation: 0.12,
        brightness: 0.12,
        bark: 0.08,
        spring: SeasonKey {
            tint: [0.83, 1.42, 0.125],
            strength: 0.45 / 8.0,
        },
        autumn: SeasonKey {
            tint: [4.0, 1.0, 0.1],
            strength: 0.85 / 8.0,
        },
        late_autumn: SeasonKey {
            tint: [2.6, 0.45, 0.13],
            strength: 0.9 / 8.0,
        },
    };

    /// [`SpeciesColour::EVERGREEN`] for a species whose name (an atlas folder's or a path's
    /// last part, less `.atlas`) has one of [`EVERGREEN_NAMES`] as a word (`scots_pine`,
    /// `Pine-2`; not `alpine`), else [`SpeciesColour::DECIDUOUS`].
    pub fn by_name(name: &str) -> SpeciesColour {
        let last = name
            .rsplit(['/', '\\'])
            .find(|p| !p.is_empty())
            .unwrap_or(name)
            .to_lowercase();
        let stem = last.strip_suffix(".atlas").unwrap_or(&last);
        let mut words = stem.split(|c: char| !c.is_alphabetic());
        if words.any(|w| EVERGREEN_NAMES.contains(&w)) {
            SpeciesColour::EVERGREEN
        } else {
            SpeciesColour::DECIDUOUS
        }
    }

    /// Every value in its range, or what is not.
    pub fn check(&self) -> Result<(), String> {
        let ranged = |what: &str, v: f32, hi: f32| {
            if (0.0..=hi).contains(&v) {
                Ok(())
            } else {
                Err(format!("{what} is {v}, outside 0 to {hi}"))
            }
        };
        ranged("hue_deg", self.hue_deg, 60.0)?;
        ranged("saturation", self.saturation, 1.0)?;
        ranged("brightness", self.brightness, 1.0)?;
        ranged("bark", self.bark, 1.0)?;
        for (name, k) in [
            ("spring", self.spring),
            ("autumn", self.autumn),
            ("late_autumn", self.late_autumn),
        ] {
            for t in k.tint {
                ranged(&format!("{name}'s tint"), t, 8.0)?;
            }
            ranged(&format!("{name}'s strength"), k.strength, 1.0)?;
        }
        Ok(())
    }

    /// The species' GPU record at `amount` ([`TreeColour`]).
    pub fn gpu(&self, amount: f32) -> TreeColour {
        let key = |k: SeasonKey| [k.tint[0], k.tint[1], k.tint[2], k.strength];
        TreeColour {
            amplitude: [
                self.hue_deg.to_radians() * amount,
                self.saturation * amount,
                self.brightness * amount,
                self.bark * amount,
            ],
            phase: [SEASON_SPREAD * amount, 0.0, 0.0, 0.0],
            spring: key(self.spring),
            autumn: key(self.autumn),
            late_autumn: key(self.late_autumn),
        }
    }
}

/// A forest's colouring: how much its trees vary, each species' colours, and the instances
/// given an explicit value.
#[derive(Clone, Debug, PartialEq)]
pub struct Colouring {
    /// Scale of every species' amplitudes and of the season's spread, 0 (every tree of a
    /// species alike) to [`MAX_AMOUNT`]; 1 is natural.
    pub amount: f32,
    /// One per species of the forest.
    pub species: Vec<SpeciesColour>,
    /// Empty, or one per instance: its value in `[0, 1]` in place of its hash, or a negative
    /// number for the hash.
    pub explicit: Vec<f32>,
}

impl Colouring {
    /// `amount` for `species` species, none explicit.
    pub fn new(amount: f32, species: Vec<SpeciesColour>) -> Self {
        Self {
            amount,
            species,
            explicit: Vec::new(),
        }
    }

    /// Consistent with a forest of `species` species and `instances` instances, or what is not.
    pub fn check(&self, species: usize, instances: usize) -> Result<(), String> {
        if !(0.0..=MAX_AMOUNT).contains(&self.amount) {
            return Err(format!(
                "colour variation amount {} is outside 0 to {MAX_AMOUNT}",
                self.amount
            ));
        }
        if self.species.len() != species {
            return Err(format!(
                "colours for {} species but the forest has {species}",
                self.species.len()
            ));
        }
        for (k, s) in self.species.iter().enumerate() {
            s.check()
                .map_err(|e| format!("species {k}'s colour: {e}"))?;
        }
        if !self.explicit.is_empty() && self.explicit.len() != instances {
            return Err(format!(
                "{} explicit colour values for {instances} instances",
                self.explicit.len()
            ));
        }
        if let Some(k) = self.explicit.iter().position(|v| v.is_nan() || *v > 1.0) {
            return Err(format!(
                "instance {k}'s colour value is {}, not in 0 to 1 (or negative for its hash)",
                self.explicit[k]
            ));
        }
        Ok(())
    }

    /// The code the GPU's instance record carries for instance `k` ([`explicit_code`]; 0: its
    /// hash).
    pub fn code(&self, k: usize) -> u32 {
        self.value(k).map_or(0, explicit_code)
    }

    /// Instance `k`'s explicit value (`None`: none, or a negative number, −0 included: its
    /// hash).
    pub fn value(&self, k: usize) -> Option<f32> {
        self.explicit
            .get(k)
            .copied()
            .filter(|v| !v.is_sign_negative())
    }
}

/// A species' colours as every method's shaders read them (`TreeColour` in `tint.wgsl`;
/// 80 bytes): the amplitudes already scaled by the forest's amount.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct TreeColour {
    /// Hue turn (radians), saturation, brightness, bark brightness: the largest changes.
    pub amplitude: [f32; 4],
    /// x: the season's spread between trees (fraction of the ramp); yzw unused.
    pub phase: [f32; 4],
    /// The spring key: tint (rgb), strength (w).
    pub spring: [f32; 4],
    /// The autumn key.
    pub autumn: [f32; 4],
    /// The late-autumn key.
    pub late_autumn: [f32; 4],
}

impl TreeColour {
    /// No variation, no ramp: every tree keeps its model's colours.
    pub const NONE: TreeColour = TreeColour {
        amplitude: [0.0; 4],
        phase: [0.0; 4],
        spring: [1.0, 1.0, 1.0, 0.0],
        autumn: [1.0, 1.0, 1.0, 0.0],
        late_autumn: [1.0, 1.0, 1.0, 0.0],
    };
}

/// The instance code of an explicit value `v ∈ [0, 1]`: bit 31 set, the value in 24 bits.
pub fn explicit_code(v: f32) -> u32 {
    0x8000_0000 | (v.clamp(0.0, 1.0) * 16_777_215.0).round() as u32
}

/// The key a tree's numbers are hashed from: its instance index, or its explicit code.
pub fn key(instance: u32, code: u32) -> u32 {
    if code == 0 { instance } else { code }
}

/// A number in `[0, 1)` from a 32-bit key (the PCG hash of `instance_hash` in common.wgsl).
pub fn hash(key: u32) -> f32 {
    let mut h = key.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    h = ((h >> ((h >> 28) + 4)) ^ h).wrapping_mul(277_803_737);
    (h >> 8) as f32 / 16_777_216.0
}

/// One round of the PCG hash of a 32-bit key, all 32 bits (`tint_mix` in tint.wgsl).
pub fn mix(key: u32) -> u32 {
    let h = key.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    ((h >> ((h >> 28) + 4)) ^ h).wrapping_mul(277_803_737)
}

/// A tree's four numbers (`tree_randoms` in tint.wgsl): hue, saturation and brightness in
/// `[−1, 1)`, the season's phase in `[−1, 1)`. Each is the hash of `mix(key) · 4 + 1 + i`
/// (wrapping): the mix first, so that every bit of an explicit code counts (times 4 drops the
/// top two) and no tree's numbers are those of the hybrid's band jitter.
pub fn randoms(key: u32) -> [f32; 4] {
    let k = mix(key).wrapping_mul(4);
    std::array::from_fn(|i| 2.0 * hash(k.wrapping_add(1 + i as u32)) - 1.0)
}

fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::from_array(LUMA))
}

/// The leaves' key at ramp position `s ∈ [0, 1]` (tint rgb, strength), linear between
/// spring (0), summer (⅓: no change), autumn (⅔) and late autumn (1).
pub fn season_key(c: &TreeColour, s: f32) -> [f32; 4] {
    let summer = [1.0, 1.0, 1.0, 0.0];
    let t = s.clamp(0.0, 1.0) * 3.0;
    let (a, b, f) = if t < 1.0 {
        (c.spring, summer, t)
    } else if t < 2.0 {
        (summer, c.autumn, t - 1.0)
    } else {
        (c.autumn, c.late_autumn, (t - 2.0).min(1.0))
    };
    std::array::from_fn(|i| a[i] + (b[i] - a[i]) * f)
}

/// The albedo (linear RGB, not premultiplied) that every method draws for a point of albedo
/// `a` and translucency `tau` of the tree whose [`key`] is `key`, of a species coloured `c`,
/// in `season` (0 to 1; negative: the model's own colours). `tree_albedo` in tint.wgsl
/// mirrors it operation for operation.
pub fn tree_albedo(a: Vec3, tau: f32, key: u32, c: &TreeColour, season: f32) -> Vec3 {
    if c.amplitude == [0.0; 4] && season < 0.0 {
        return a;
    }
    let r = randoms(key);
    let leafness = (tau / LEAF_TRANSLUCENCY).clamp(0.0, 1.0);
    // Hue: Rodrigues' rotation about the unit grey axis k.
    let k = Vec3::splat(0.577_350_26);
    let (sin, cos) = (r[0] * c.amplitude[0]).sin_cos();
    let mut leaf = a * cos + k.cross(a) * sin + k * (k.dot(a) * (1.0 - cos));
    let y = luminance(leaf);
    leaf = Vec3::splat(y) + (leaf - Vec3::splat(y)) * (1.0 + r[1] * c.amplitude[1]);
    leaf *= 1.0 + r[2] * c.amplitude[2];
    if season >= 0.0 {
        let key = season_key(c, season + r[3] * c.phase[0]);
        let target = Vec3::new(key[0], key[1], key[2]) * luminance(leaf).max(0.0);
        leaf += (target - leaf) * key[3];
    }
    let bark = a * (1.0 + r[2] * c.amplitude[3]);
    (bark + (leaf - bark) * leafness).clamp(Vec3::ZERO, Vec3::ONE)
}

/// CIELAB (D65 white) of a linear sRGB colour: L* 0 to 100.
pub fn lab(c: Vec3) -> Vec3 {
    // Linear sRGB to XYZ (D65), each over the white's.
    let x = (0.412_456_4 * c.x + 0.357_576_1 * c.y + 0.180_437_5 * c.z) / 0.950_47;
    let y = 0.212_672_9 * c.x + 0.715_152_2 * c.y + 0.072_175 * c.z;
    let z = (0.019_333_9 * c.x + 0.119_192 * c.y + 0.950_304_1 * c.z) / 1.088_83;
    let f = |t: f32| {
        if t > 216.0 / 24_389.0 {
            t.cbrt()
        } else {
            (24_389.0 / 27.0 * t + 16.0) / 116.0
        }
    };
    let (fx, fy, fz) = (f(x), f(y), f(z));
    Vec3::new(116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz))
}

/// ΔE*ab (CIE 1976) between two linear sRGB colours.
pub fn delta_e(a: Vec3, b: Vec3) -> f32 {
    lab(a).distance(lab(b))
}

/// A frame's season is `None` or a number from 0 to 1, or what is wrong.
pub fn check_season(season: Option<f32>) -> Result<(), String> {
    match season {
        Some(s) if !(0.0..=1.0).contains(&s) => Err(format!(
            "season {s} is outside 0 (spring) to 1 (late autumn)"
        )),
        _ => Ok(()),
    }
}

/// A season by its name (`spring`, `summer`, `autumn`, `late-autumn`) or its place on the
/// ramp, a number from 0 (spring) to 1 (late autumn).
pub fn parse_season(s: &str) -> Result<f32, String> {
    let t = s.trim();
    if let Some((_, v)) = SEASONS
        .iter()
        .find(|(n, _)| n.eq_ignore_ascii_case(t) || n.replace('-', "_") == t.to_lowercase())
    {
        return Ok(*v);
    }
    match t.parse::<f32>() {
        Ok(v) if (0.0..=1.0).contains(&v) => Ok(v),
        Ok(v) => Err(format!(
            "season {v} is outside 0 (spring) to 1 (late autumn)"
        )),
        Err(_) => Err(format!(
            "season {t:?} is neither a number from 0 to 1 nor one of spring, summer, autumn, \
             late-autumn"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lab_has_its_white_point_and_primaries() {
        assert!(
            (lab(Vec3::ONE) - Vec3::new(100.0, 0.0, 0.0))
                .abs()
                .max_element()
                < 0.01
        );
        assert!(lab(Vec3::ZERO).abs().max_element() < 1e-6);
        // sRGB red: L* 53.24, a* 80.09, b* 67.20.
        let r = lab(Vec3::X);
        assert!(
            (r - Vec3::new(53.24, 80.09, 67.20)).abs().max_element() < 0.05,
            "{r}"
        );
        assert!((delta_e(Vec3::X, Vec3::X) - 0.0).abs() < 1e-6);
    }

    const GREEN: Vec3 = Vec3::new(0.06, 0.14, 0.03);
    const BARK: Vec3 = Vec3::new(0.12, 0.08, 0.05);

    #[test]
    fn no_colouring_and_no_season_return_the_albedo_bit_for_bit() {
        for key in [0, 1, 77, u32::MAX] {
            for a in [GREEN, BARK, Vec3::new(0.3, 1.0, 0.0)] {
                let out = tree_albedo(a, LEAF_TRANSLUCENCY, key, &TreeColour::NONE, -1.0);
                assert_eq!(
                    out.to_array().map(f32::to_bits),
                    a.to_array().map(f32::to_bits)
                );
            }
        }
    }

    #[test]
    fn a_zero_turn_keeps_the_colour_and_the_hue_turn_keeps_grey() {
        let c = SpeciesColour::DECIDUOUS.gpu(0.0);
        // Amount 0 with summer: the season's strength is 0 and the spread 0.
        let out = tree_albedo(GREEN, LEAF_TRANSLUCENCY, 5, &c, 1.0 / 3.0);
        assert!((out - GREEN).abs().max_element() < 1e-6, "{out}");
        // A grey stays grey under any turn (the axis of the rotation), whatever the key.
        let c = SpeciesColour::DECIDUOUS.gpu(3.0);
        let grey = Vec3::splat(0.3);
        for key in 0..50 {
            let r = randoms(key);
            let out = tree_albedo(grey, LEAF_TRANSLUCENCY, key, &c, -1.0);
            let want = 0.3 * (1.0 + r[2] * c.amplitude[2]);
            assert!(
                (out - Vec3::splat(want)).abs().max_element() < 1e-5,
                "{out} {want}"
            );
        }
    }

    #[test]
    fn bark_keeps_its_hue_and_every_season() {
        let c = SpeciesColour::DECIDUOUS.gpu(1.0);
        for key in 0..100 {
            let calm = tree_albedo(BARK, 0.0, key, &c, -1.0);
            for s in [0.0, 0.2, 1.0 / 3.0, 0.5, 2.0 / 3.0, 0.9, 1.0] {
                assert_eq!(tree_albedo(BARK, 0.0, key, &c, s), calm);
            }
            // Only its brightness changes, by at most the bark amplitude.
            let ratio = calm / BARK;
            assert!((ratio - Vec3::splat(ratio.x)).abs().max_element() < 1e-5);
            assert!((ratio.x - 1.0).abs() <= c.amplitude[3] + 1e-6);
        }
    }

    #[test]
    fn trees_differ_by_about_the_amplitudes_and_autumn_turns_leaves_red() {
        let c = SpeciesColour::DECIDUOUS.gpu(1.0);
        let summer: Vec<Vec3> = (0..400)
            .map(|k| lab(tree_albedo(GREEN, LEAF_TRANSLUCENCY, k, &c, -1.0)))
            .collect();
        let mean = summer.iter().copied().sum::<Vec3>() / summer.len() as f32;
        let spread = (summer
            .iter()
            .map(|l| (*l - mean).length_squared())
            .sum::<f32>()
            / summer.len() as f32)
            .sqrt();
        // Visible (a just-noticeable difference is about 2) but natural.
        assert!((2.0..12.0).contains(&spread), "ΔE spread {spread}");
        let base = lab(GREEN);
        let autumn = (0..400)
            .map(|k| lab(tree_albedo(GREEN, LEAF_TRANSLUCENCY, k, &c, 2.0 / 3.0)))
            .sum::<Vec3>()
            / 400.0;
        // a* from green (negative) to red (positive), b* more yellow.
        assert!(base.y < -5.0 && autumn.y > 10.0, "{base} {autumn}");
        assert!(autumn.z > base.z, "{base} {autumn}");
        // An evergreen barely turns.
        let e = SpeciesColour::EVERGREEN.gpu(1.0);
        let pine = (0..400)
            .map(|k| lab(tree_albedo(GREEN, LEAF_TRANSLUCENCY, k, &e, 2.0 / 3.0)))
            .sum::<Vec3>()
            / 400.0;
        assert!(pine.y < -5.0, "{pine}");
    }

    #[test]
    fn trees_turn_one_by_one() {
        // Halfway from summer to autumn some trees have turned further than others.
        let c = SpeciesColour::DECIDUOUS.gpu(1.0);
        let a: Vec<f32> = (0..200)
            .map(|k| lab(tree_albedo(GREEN, LEAF_TRANSLUCENCY, k, &c, 0.5)).y)
            .collect();
        let (lo, hi) = a
            .iter()
            .fold((f32::MAX, f32::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
        assert!(hi - lo > 10.0, "a* from {lo} to {hi}");
    }

    #[test]
    fn randoms_are_spread_and_explicit_values_replace_the_hash() {
        let n = 4096;
        let mut mean = [0.0f32; 4];
        for k in 0..n {
            let r = randoms(k);
            for i in 0..4 {
                assert!((-1.0..1.0).contains(&r[i]));
                mean[i] += r[i] / n as f32;
            }
        }
        assert!(mean.iter().all(|m| m.abs() < 0.05), "{mean:?}");
        let mut c = Colouring::new(1.0, vec![SpeciesColour::DECIDUOUS]);
        assert_eq!(c.code(3), 0);
        c.explicit = vec![-1.0, 0.25, 0.25, -0.0, 0.0];
        assert_eq!(c.code(0), 0);
        assert_eq!(c.code(1), c.code(2));
        assert_ne!(key(1, c.code(1)), 1);
        // −0 is the hash; +0 an explicit value.
        assert_eq!(c.code(3), 0);
        assert_ne!(c.code(4), 0);
        // An explicit value's numbers are not those of the hashed tree whose index its low
        // bits spell (the top bits count).
        for v in [0.0, 0.25, 0.5, 1.0] {
            let code = explicit_code(v);
            assert_ne!(randoms(code), randoms(code & 0x00ff_ffff), "value {v}");
        }
        c.explicit.truncate(3);
        assert!(c.check(1, 3).is_ok());
        assert!(c.check(1, 4).unwrap_err().contains("3 explicit"));
        c.explicit[2] = f32::NAN;
        assert!(c.check(1, 3).unwrap_err().contains("instance 2"));
        c.explicit.clear();
        c.amount = 4.0;
        assert!(c.check(1, 3).unwrap_err().contains("amount 4"));
        c.amount = 1.0;
        c.species[0].autumn.strength = 2.0;
        assert!(
            c.check(1, 3)
                .unwrap_err()
                .contains("autumn's strength is 2")
        );
    }

    #[test]
    fn evergreens_are_told_by_a_word_of_the_atlas_name() {
        let e = |n: &str| SpeciesColour::by_name(n) == SpeciesColour::EVERGREEN;
        assert!(e("pine") && e("out/atlases/pine.atlas") && e("scots_pine.atlas"));
        assert!(e("Spruce-2") && e("C:\\trees\\fir.atlas") && e("pine.atlas/"));
        assert!(!e("alpine.atlas") && !e("first") && !e("pines/oak.atlas") && !e("oak"));
    }

    #[test]
    fn seasons_parse_by_name_and_number() {
        assert_eq!(parse_season("autumn"), Ok(2.0 / 3.0));
        assert_eq!(parse_season("Late-Autumn"), Ok(1.0));
        assert_eq!(parse_season("late_autumn"), Ok(1.0));
        assert_eq!(parse_season("0.25"), Ok(0.25));
        assert!(parse_season("1.5").unwrap_err().contains("outside"));
        assert!(parse_season("NaN").is_err());
        assert!(parse_season("winter").unwrap_err().contains("neither"));
    }
}
