//! Wind: one model of how trees move, evaluated alike by every method on the GPU
//! (`wind.wgsl` in forest-render, operation for operation) and here on the CPU.
//!
//! The frame carries the wind ([`Wind`]: where it blows, its mean speed, its gustiness and the
//! instant) in the camera uniform. Every method moves a tree's points by [`Wind::swayed`], a
//! function of the point's world position, the tree's foot and height and its instance
//! index, so that the same point of the same tree moves alike whichever form draws it: a
//! model's vertex, a quad's corner, a billboard's corner. Each form samples the motion at its
//! own vertices: per vertex near (geometry), per node further (a quad's corners), per tree
//! far (a composited quad's or a billboard's corners). Nothing is baked: every atlas sways.
//!
//! The motion, after the main and detail bending of GPU Gems 3 ch. 16 (CryEngine):
//!
//! - **Gusts** travel downwind at the mean speed as waves over the canopy (two sines along the
//!   wind, 37 m and 17 m long, longer in a strong wind so that they pass a tree no more often
//!   than every [`GUST_PERIODS`], their crests bent across it), so neighbouring trees lean in
//!   turn, not in phase. The speed a tree feels is `u = speed · (1 + gustiness · n)`,
//!   `n ∈ [−1, 1]` the waves at its foot.
//! - **Bending** of the whole tree, its top moved by `height · (lean + sway)`: the lean grows
//!   with the drag, `BEND · u²`, saturating at [`MAX_LEAN`]; the sway oscillates about it at
//!   the tree's own frequency (`2.2 / √height` Hz, 0.15 to 2 Hz: tall trees sway slowly), with
//!   a phase from a hash of the instance, along the wind and, less, across it. A point at
//!   height `h` above the foot moves by the top's offset times `h / height`, then back onto
//!   its distance from the foot, so the tree turns about its foot instead of stretching. The
//!   profile is linear in height so that a quad or a card, whose corners move and whose
//!   inside follows them linearly, moves its inside as the model's own points move: a
//!   quadratic bend drew coarse quads and billboards swaying up to twice as far as the
//!   model under them (measured: a storm shifted a bush's crown 0.68 px as geometry, 1.08 px
//!   as quads, 1.77 px as an impostor).
//! - **Flutter** of branches and leaves: a few centimetres at 2 to 3 Hz, growing with the
//!   distance from the trunk's axis and the height, mostly vertical, its phase varying
//!   smoothly through the crown (a wave through space), so a branch moves as one.
//!
//! With no wind (speed 0) every point stays exactly where it is.

use glam::{Vec2, Vec3};

/// The highest mean wind speed taken (m/s): a violent storm on the Beaufort scale (11) is
/// 28.5 to 32.6 m/s, a hurricane from 32.7; beyond 50 m/s the model means nothing.
pub const MAX_SPEED: f32 = 50.0;
/// The largest instant taken (seconds, either sign; about 28 hours): f32 phases stay within
/// a sixtieth of a cycle up to it. Hosts running longer wrap their clock.
pub const MAX_TIME: f32 = 1.0e5;
/// The gustiness of [`Wind::new`]: gusts from half to one and a half times the mean speed.
pub const DEFAULT_GUSTINESS: f32 = 0.5;
/// The lean's growth with the squared speed (fraction of the height per (m/s)²).
pub const BEND: f32 = 2.5e-4;
/// The lean a tree approaches in the strongest wind (a fraction of its height).
pub const MAX_LEAN: f32 = 0.2;
/// Flutter amplitude per m/s of wind at the crown's rim and top (metres).
pub const FLUTTER: f32 = 0.004;
/// A point higher (or lower, below the foot) than this many times the tree's height bends as
/// if at it (a bounding sphere's top lies above the model's).
pub const MAX_RELATIVE_HEIGHT: f32 = 1.5;

/// The shortest periods of the two gust waves (seconds): their wavelengths grow with the
/// mean speed beyond 37 m and 17 m so that a storm's gusts come no faster than a breeze's
/// (gusts lengthen with the wind; a tree's lean cannot follow faster changes).
pub const GUST_PERIODS: [f32; 2] = [4.6, 2.1];

const TAU: f32 = std::f32::consts::TAU;

/// The wind of a frame.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Wind {
    /// The azimuth it blows towards, degrees from +Z towards +X (as the sun's azimuth).
    pub towards_deg: f32,
    /// Mean speed, m/s: 0 (calm) to [`MAX_SPEED`].
    pub speed: f32,
    /// How much gusts vary the speed: 0 (steady) to 1 (from calm to twice the mean).
    pub gustiness: f32,
    /// The instant, seconds: within ±[`MAX_TIME`].
    pub time: f32,
}

impl Default for Wind {
    /// Calm.
    fn default() -> Self {
        Self::CALM
    }
}

/// Where and how tall a tree stands, for [`Wind::swayed`]: what every method knows of an
/// instance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SwayedTree {
    /// The tree's foot (world, metres): its instance's position.
    pub foot: Vec3,
    /// Its height above the foot (metres, > 0): the top of its bounding sphere, scaled.
    pub height: f32,
    /// Its crown's radius (metres, > 0): the bounding sphere's, scaled.
    pub radius: f32,
    /// Its instance index (the phase of its sway).
    pub seed: u32,
}

impl SwayedTree {
    /// The tree of an instance at `foot` scaled by `scale`, whose species' bounding sphere
    /// (object space, the foot at y = 0) has its centre at height `centre_y` and radius
    /// `radius`; `seed` its instance index. The height is the sphere's top (`wind.wgsl`'s
    /// `wind_height`).
    pub fn from_sphere(foot: Vec3, scale: f32, centre_y: f32, radius: f32, seed: u32) -> Self {
        Self {
            foot,
            height: ((centre_y + radius) * scale).max(1e-3),
            radius: radius * scale,
            seed,
        }
    }
}

impl Wind {
    /// No wind: nothing moves.
    pub const CALM: Self = Self {
        towards_deg: 0.0,
        speed: 0.0,
        gustiness: DEFAULT_GUSTINESS,
        time: 0.0,
    };

    /// A wind blowing towards `towards_deg` at `speed` m/s, [`DEFAULT_GUSTINESS`], at time 0.
    pub fn new(towards_deg: f32, speed: f32) -> Self {
        Self {
            towards_deg,
            speed,
            ..Self::CALM
        }
    }

    /// The same wind at instant `time` (seconds).
    pub fn at(self, time: f32) -> Self {
        Self { time, ..self }
    }

    /// Check every field against its bound; the error names the field and the bound.
    pub fn validate(&self) -> Result<(), String> {
        if !self.towards_deg.is_finite() {
            return Err(format!(
                "wind direction {} is not a number of degrees",
                self.towards_deg
            ));
        }
        if !(self.speed.is_finite() && (0.0..=MAX_SPEED).contains(&self.speed)) {
            return Err(format!(
                "wind speed {} m/s: expected 0 to {MAX_SPEED} m/s",
                self.speed
            ));
        }
        if !(self.gustiness.is_finite() && (0.0..=1.0).contains(&self.gustiness)) {
            return Err(format!(
                "wind gustiness {}: expected 0 (steady) to 1",
                self.gustiness
            ));
        }
        if !(self.time.is_finite() && self.time.abs() <= MAX_TIME) {
            return Err(format!(
                "wind time {} s: expected within ±{MAX_TIME:e} s (wrap a longer clock)",
                self.time
            ));
        }
        Ok(())
    }

    /// The unit direction it blows towards, (x, z) in the world.
    pub fn direction(&self) -> Vec2 {
        let a = self.towards_deg.to_radians();
        Vec2::new(a.sin(), a.cos())
    }

    /// The camera uniform's two vectors: (direction x, direction z, speed, gustiness) and
    /// (time, 0, 0, 0).
    pub fn uniform(&self) -> [[f32; 4]; 2] {
        let d = self.direction();
        [
            [d.x, d.y, self.speed, self.gustiness],
            [self.time, 0.0, 0.0, 0.0],
        ]
    }

    /// The farthest any point of a tree of `height` metres moves at any instant (metres): a
    /// static bound, for a host's own bounding boxes. The culls use the tighter
    /// [`Wind::reach_now`].
    pub fn reach(&self, height: f32) -> f32 {
        reach(&self.uniform(), height)
    }

    /// The farthest any point of `tree` is moved at this instant (metres): at most
    /// [`Wind::reach`] of its height, and on average a fifth of it, since it takes the
    /// gust at the tree's foot and the phase of its sway now instead of their worst. What
    /// every cull grows the tree's bounding sphere by.
    pub fn reach_now(&self, tree: &SwayedTree) -> f32 {
        reach_now(&self.uniform(), tree)
    }

    /// Where point `p` (world, metres) of `tree` is in this wind.
    pub fn swayed(&self, p: Vec3, tree: &SwayedTree) -> Vec3 {
        swayed(&self.uniform(), p, tree)
    }
}

/// [`Wind::reach`] from the uniform's vectors (the static bound; the shaders use `wind_reach_now`).
pub fn reach(w: &[[f32; 4]; 2], height: f32) -> f32 {
    let [_, _, speed, gust] = w[0];
    if speed <= 0.0 {
        return 0.0;
    }
    let u = speed * (1.0 + gust);
    let lean = lean_of(u);
    let top = height * (lean * (1.25 + 0.8 * gust)) * MAX_RELATIVE_HEIGHT;
    2.0 * (top + FLUTTER * u * MAX_RELATIVE_HEIGHT)
}

/// The lean (top's offset over the height) at speed `u`: `BEND · u²`, saturating at
/// [`MAX_LEAN`].
fn lean_of(u: f32) -> f32 {
    let b = BEND * u * u;
    b / (1.0 + b / MAX_LEAN)
}

/// A 32-bit integer hash (PCG's output permutation), the same on the GPU.
pub fn hash(x: u32) -> u32 {
    let h = x.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let h = ((h >> ((h >> 28) + 4)) ^ h).wrapping_mul(277_803_737);
    (h >> 22) ^ h
}

/// [`hash`] as a number in [0, 1).
fn hash01(x: u32) -> f32 {
    (hash(x) >> 8) as f32 / 16_777_216.0
}

/// The gust waves at a foot `at` (world x, z) at `time`: in [−1, 1], travelling downwind
/// (`dir`) at `speed`.
fn gusts(dir: Vec2, speed: f32, time: f32, at: Vec2) -> f32 {
    let s = at.dot(dir) - speed * time;
    let c = at.dot(Vec2::new(-dir.y, dir.x));
    let long = (speed * GUST_PERIODS[0]).max(37.0);
    let short = (speed * GUST_PERIODS[1]).max(17.0);
    0.6 * (TAU * s / long + 0.9 * (TAU * c / 53.0).sin()).sin()
        + 0.4 * (TAU * s / short + 2.1 + 0.7 * (TAU * c / 29.0).sin()).sin()
}

/// A tree's bend at the frame's instant: the top's offset over the height (world x, z, a
/// fraction of the height), the speed `u` it feels (m/s) and its sway's phase in [0, 1)
/// (`wind.wgsl`'s `wind_bend`). `None` in calm.
fn bend(w: &[[f32; 4]; 2], foot: Vec3, height: f32, seed: u32) -> Option<(Vec2, f32, f32)> {
    let [dx, dz, speed, gust] = w[0];
    let time = w[1][0];
    if speed <= 0.0 {
        return None;
    }
    let dir = Vec2::new(dx, dz);
    let u = (speed * (1.0 + gust * gusts(dir, speed, time, Vec2::new(foot.x, foot.z)))).max(0.0);
    let lean = lean_of(u);
    // The sway about the lean, at the tree's own frequency and phase.
    let freq = (2.2 / height.sqrt()).clamp(0.15, 2.0);
    let phase = hash01(seed);
    let along = lean * (0.25 + 0.5 * gust) * (TAU * (freq * time + phase)).sin();
    let across = lean * (0.1 + 0.3 * gust) * (TAU * (1.37 * freq * time + 2.0 * phase) + 1.0).sin();
    let top = dir * (lean + along) + Vec2::new(-dz, dx) * across;
    Some((top, u, phase))
}

/// [`Wind::swayed`] from the uniform's vectors (`wind.wgsl`'s `swayed`).
pub fn swayed(w: &[[f32; 4]; 2], p: Vec3, tree: &SwayedTree) -> Vec3 {
    let [dx, dz, _, _] = w[0];
    let time = w[1][0];
    let foot = tree.foot;
    let height = tree.height.max(1e-3);
    let Some((top, u, phase)) = bend(w, foot, height, tree.seed) else {
        return p;
    };
    let top = Vec3::new(top.x, 0.0, top.y);
    let q = p - foot;
    // Linear in height on both sides of the foot, so that a card reaching below it (a
    // billboard over the bounding sphere) moves as the points it shows.
    let rel = (q.y / height).clamp(-MAX_RELATIVE_HEIGHT, MAX_RELATIVE_HEIGHT);
    // Flutter: growing from the trunk's axis outwards and upwards, a wave through the crown.
    let rim = (Vec2::new(q.x, q.z).length() / tree.radius.max(1e-3)).min(1.0);
    let wave = q.dot(Vec3::new(1.9, 2.3, 1.7)) + TAU * phase;
    let flutter_freq = 2.0 + phase;
    let flutter = FLUTTER * u * rim * rel.max(0.0) * (TAU * flutter_freq * time + wave).sin();
    let offset = top * (height * rel) + Vec3::new(0.4 * dx, 0.6, 0.4 * dz) * flutter;
    // Back onto the point's distance from the foot: the trunk bends, it does not stretch.
    let moved = q + offset;
    let len = moved.length();
    if len > 0.0 {
        foot + moved * (q.length() / len)
    } else {
        p
    }
}

/// [`Wind::reach_now`] from the uniform's vectors (`wind.wgsl`'s `wind_reach_now`).
///
/// A point `q` from the foot is offset by `o`, `|o| ≤ O = |top| · height · R + |f| · F · u ·
/// R` (`R` = [`MAX_RELATIVE_HEIGHT`], `F` = [`FLUTTER`], `f` the flutter's direction), then
/// put back at its distance from the foot. That turns `q` by the angle `θ` it sees `q + o`
/// under, and moves it by the chord `2 |q| sin(θ/2) ≤ |o| / cos(θ/2)`. Since `|o| / |q| ≤ K =
/// |top| + |f| · F · u · R / height` (the bend is linear in the point's height; the flutter
/// grows with its height and its distance from the axis), `sin θ ≤ K`, and for `K < 1` the
/// chord is at most `O / √((1 + √(1 − K²)) / 2)`; otherwise at most `2 O`. A hundredth more
/// covers the rounding of either side.
pub fn reach_now(w: &[[f32; 4]; 2], tree: &SwayedTree) -> f32 {
    let height = tree.height.max(1e-3);
    let Some((top, u, _)) = bend(w, tree.foot, height, tree.seed) else {
        return 0.0;
    };
    let [dx, dz, _, _] = w[0];
    let f = Vec3::new(0.4 * dx, 0.6, 0.4 * dz).length() * FLUTTER * u * MAX_RELATIVE_HEIGHT;
    let t = top.length();
    let most = t * height * MAX_RELATIVE_HEIGHT + f;
    let k = t + f / height;
    let turn = if k < 1.0 {
        1.0 / ((1.0 + (1.0 - k * k).sqrt()) * 0.5).sqrt()
    } else {
        2.0
    };
    1.01 * turn * most
}

/// Parse a wind given as `TOWARDS,SPEED` (as `--wind` takes it): the azimuth it blows
/// towards in degrees and the mean speed in m/s, both finite numbers (the bounds are
/// [`Wind::validate`]'s, which names them).
pub fn parse_towards_speed(s: &str) -> Result<(f32, f32), String> {
    let parts: Vec<&str> = s.split(',').collect();
    let [towards, speed] = parts.as_slice() else {
        return Err(format!(
            "{s:?}: expected TOWARDS,SPEED (degrees, m/s), e.g. 60,8"
        ));
    };
    let num = |x: &str, what: &str| {
        x.trim()
            .parse::<f32>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("{x:?} is not a finite {what}"))
    };
    Ok((
        num(towards, "number of degrees")?,
        num(speed, "speed in m/s")?,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tree() -> SwayedTree {
        SwayedTree {
            foot: Vec3::new(3.0, 1.0, -2.0),
            height: 12.0,
            radius: 5.0,
            seed: 7,
        }
    }

    #[test]
    fn calm_moves_nothing_and_the_foot_never_moves() {
        let p = Vec3::new(4.0, 9.0, -1.0);
        assert_eq!(Wind::CALM.swayed(p, &tree()), p);
        assert_eq!(Wind::CALM.reach(12.0), 0.0);
        assert_eq!(Wind::CALM.reach_now(&tree()), 0.0);
        let storm = Wind::new(70.0, 30.0).at(12.5);
        assert_eq!(storm.swayed(tree().foot, &tree()), tree().foot);
    }

    #[test]
    fn the_tree_leans_downwind_more_the_higher_and_stays_within_its_reach() {
        let t = tree();
        for towards in [0.0f32, 90.0, 215.0] {
            let wind = Wind {
                gustiness: 0.0,
                ..Wind::new(towards, 12.0)
            };
            let dir = wind.direction();
            let mut last = 0.0;
            for h in [2.0f32, 5.0, 8.0, 12.0] {
                // The trunk: the mean over a sway period leans downwind, more at height.
                let p = t.foot + Vec3::Y * h;
                let mean = (0..200)
                    .map(|k| wind.at(k as f32 * 0.05).swayed(p, &t) - p)
                    .fold(Vec3::ZERO, |a, b| a + b)
                    / 200.0;
                let downwind = mean.x * dir.x + mean.z * dir.y;
                assert!(
                    downwind > last,
                    "{towards}: at {h} m {downwind} after {last}"
                );
                last = downwind;
            }
            // About BEND·u²·height at the top (within the sway's spread).
            let want = lean_of(12.0) * 12.0;
            assert!((last - want).abs() < 0.35 * want, "{last} vs {want}");
        }
        // No point of the tree moves farther than the reach, over a minute of gusts.
        let wind = Wind::new(40.0, 25.0);
        wind.validate().unwrap();
        let reach = wind.reach(t.height);
        for k in 0..600 {
            let w = wind.at(k as f32 * 0.1);
            for p in [
                Vec3::new(0.0, 12.0, 0.0),
                Vec3::new(5.0, 16.0, 0.0),
                Vec3::new(-4.0, 7.0, 3.0),
            ] {
                let p = t.foot + p;
                assert!((w.swayed(p, &t) - p).length() <= reach, "{k}");
            }
        }
    }

    /// The instant's reach holds every point of the tree, at every instant, in any wind and
    /// for any tree (a sapling to a sequoia, a crown far wider than tall), including points
    /// near the foot, below it and above the bounding sphere; it never exceeds the static
    /// reach, and in a gusty wind it is on average well under it.
    #[test]
    fn the_instants_reach_holds_every_point_and_is_tighter_than_the_static_one() {
        let mut rng = crate::noise::SplitMix64(11);
        let mut unit = || rng.next_f32();
        let (mut ratio, mut n) = (0.0f64, 0usize);
        for case in 0..60 {
            let height = 0.3 + 80.0 * unit() * unit();
            let t = SwayedTree {
                foot: Vec3::new(200.0 * unit() - 100.0, 5.0 * unit(), 200.0 * unit() - 100.0),
                height,
                radius: height * (0.05 + 1.5 * unit()),
                seed: case,
            };
            let wind = Wind {
                towards_deg: 360.0 * unit(),
                speed: if case % 7 == 0 {
                    MAX_SPEED
                } else {
                    MAX_SPEED * unit()
                },
                gustiness: if case % 5 == 0 { 1.0 } else { unit() },
                time: 0.0,
            };
            let reach = wind.reach(height);
            for k in 0..80 {
                let w = wind.at(k as f32 * 0.173 + 20.0 * unit());
                let now = w.reach_now(&t);
                assert!(now <= reach * 1.0001, "{case}/{k}: {now} over {reach}");
                ratio += (now / reach.max(1e-9)) as f64;
                n += 1;
                for _ in 0..40 {
                    let r = height * 1.6 * unit();
                    let d = Vec3::new(unit() - 0.5, unit() - 0.5, unit() - 0.5).normalize_or_zero();
                    let d = if unit() < 0.2 {
                        Vec3::Y * d.y.signum()
                    } else {
                        d
                    };
                    let p = t.foot + d * r;
                    let moved = (w.swayed(p, &t) - p).length();
                    assert!(
                        moved <= now,
                        "{case}/{k}: {moved} m beyond the reach {now} m"
                    );
                }
            }
        }
        let mean = ratio / n as f64;
        assert!(
            mean < 0.35,
            "the instant's reach is {mean} of the static one on average"
        );
    }

    #[test]
    fn gusts_travel_downwind_and_neighbours_are_not_in_phase() {
        let dir = Vec2::new(0.6, 0.8);
        // A crest at a point reaches a point 10 m downwind 1 s later at 10 m/s.
        let a = Vec2::new(3.0, 4.0);
        let b = a + dir * 10.0;
        for t in [0.0f32, 0.7, 3.1] {
            let now = gusts(dir, 10.0, t, a);
            let later = gusts(dir, 10.0, t + 1.0, b);
            assert!((now - later).abs() < 1e-4, "{now} {later}");
        }
        // Two trees side by side sway with different phases.
        let w = Wind::new(0.0, 8.0).at(3.0);
        let (mut t1, mut t2) = (tree(), tree());
        t1.seed = 1;
        t2.seed = 2;
        let p = tree().foot + Vec3::Y * 12.0;
        assert!((w.swayed(p, &t1) - w.swayed(p, &t2)).length() > 1e-3);
    }

    /// The motion is continuous in time and in space: a point's displacement changes by at
    /// most a bounded speed between instants a millisecond apart, and two points a
    /// millimetre apart (a split vertex, a leaf card's corner on its branch) stay within a
    /// millimetre of each other in the strongest wind; points at the same place move alike.
    #[test]
    fn the_motion_is_continuous_and_tears_nothing() {
        let t = tree();
        let storm = Wind {
            gustiness: 1.0,
            ..Wind::new(33.0, MAX_SPEED)
        };
        let mut rng = crate::noise::SplitMix64(5);
        let mut unit = || rng.next_f32() * 2.0 - 1.0;
        for k in 0..400 {
            let time = k as f32 * 0.37;
            let p = t.foot + Vec3::new(6.0 * unit(), 8.0 + 8.0 * unit(), 6.0 * unit());
            let now = storm.at(time).swayed(p, &t);
            let soon = storm.at(time + 1e-3).swayed(p, &t);
            // A storm sways a 12 m tree's top by ±15 % of its height at 0.64 Hz (7 m/s at
            // most) and across it by less; its gusts pass no more often than every 2.1 s
            // (before, at 50 m/s every 0.34 s, leaning and righting the tree at 30 m/s).
            assert!(
                (soon - now).length() < 1.2e-2,
                "{k}: {} m in 1 ms",
                (soon - now).length()
            );
            assert_eq!(
                storm.at(time).swayed(p, &t),
                now,
                "the same point moved otherwise"
            );
            let q = p + Vec3::new(unit(), unit(), unit()).normalize_or_zero() * 1e-3;
            let apart = (storm.at(time).swayed(q, &t) - now).length();
            assert!(apart < 2e-3, "{k}: 1 mm apart became {apart} m apart");
        }
    }

    #[test]
    fn bad_winds_are_named_with_their_bound() {
        for (w, cause) in [
            (Wind::new(f32::NAN, 5.0), "direction"),
            (Wind::new(0.0, -1.0), "0 to 50"),
            (Wind::new(0.0, f32::NAN), "wind speed"),
            (Wind::new(0.0, 1e9), "0 to 50"),
            (
                Wind {
                    gustiness: 2.0,
                    ..Wind::new(0.0, 5.0)
                },
                "gustiness",
            ),
            (Wind::new(0.0, 5.0).at(1e9), "wrap"),
            (Wind::new(0.0, 5.0).at(f32::INFINITY), "wind time"),
        ] {
            let e = w.validate().unwrap_err();
            assert!(e.contains(cause), "{w:?}: {e}");
        }
    }
}
