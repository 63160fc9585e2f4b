//! The viewer's camera controller: walk on the ground (the forest's terrain) at eye height or
//! fly, yaw and pitch from the mouse, speed from the wheel.

use std::collections::HashSet;

use glam::Vec3;
use winit::keyboard::KeyCode;

use super::EYE_HEIGHT;

/// The walker: position, yaw and pitch (radians), speed (m/s), walk or fly.
#[derive(Clone, Copy, Debug)]
pub struct Walker {
    /// Eye position.
    pub eye: Vec3,
    /// Heading about +Y (0 looks along −Z).
    pub yaw: f32,
    /// Elevation of the view (clamped to ±85°).
    pub pitch: f32,
    /// Speed in metres per second.
    pub speed: f32,
    /// Follow the ground at eye height.
    pub walk: bool,
}

impl Walker {
    /// Unit view direction.
    pub fn forward(&self) -> Vec3 {
        Vec3::new(
            self.yaw.sin() * self.pitch.cos(),
            self.pitch.sin(),
            -self.yaw.cos() * self.pitch.cos(),
        )
    }

    /// A walker at `eye` looking at `target` (fly mode unless the eye is at walking height
    /// above `ground`, the height of the ground at the eye).
    pub fn looking_at(eye: Vec3, target: Vec3, speed: f32, ground: f32) -> Self {
        let d = (target - eye).normalize_or(Vec3::NEG_Z);
        Self {
            eye,
            yaw: d.x.atan2(-d.z),
            pitch: d.y.clamp(-1.0, 1.0).asin().clamp(-1.48, 1.48),
            speed,
            walk: (eye.y - ground - EYE_HEIGHT).abs() < 1e-3,
        }
    }

    /// Move for `dt` seconds with the pressed keys over the ground `ground(x, z)` (metres):
    /// walking keeps the eye [`EYE_HEIGHT`] above it, flying at least 0.2 m above it.
    pub fn step(&mut self, keys: &HashSet<KeyCode>, dt: f32, ground: impl Fn(f32, f32) -> f32) {
        let flat = Vec3::new(self.yaw.sin(), 0.0, -self.yaw.cos());
        let right = Vec3::new(self.yaw.cos(), 0.0, self.yaw.sin());
        let ahead = if self.walk { flat } else { self.forward() };
        let mut v = Vec3::ZERO;
        let k = |c| keys.contains(&c);
        if k(KeyCode::KeyW) {
            v += ahead;
        }
        if k(KeyCode::KeyS) {
            v -= ahead;
        }
        if k(KeyCode::KeyD) {
            v += right;
        }
        if k(KeyCode::KeyA) {
            v -= right;
        }
        if !self.walk && k(KeyCode::KeyE) {
            v += Vec3::Y;
        }
        if !self.walk && k(KeyCode::KeyQ) {
            v -= Vec3::Y;
        }
        let run = if k(KeyCode::ShiftLeft) || k(KeyCode::ShiftRight) {
            4.0
        } else {
            1.0
        };
        self.eye += v.normalize_or_zero() * self.speed * run * dt;
        let floor = ground(self.eye.x, self.eye.z);
        if self.walk {
            self.eye.y = floor + EYE_HEIGHT;
        }
        self.eye.y = self.eye.y.max(floor + 0.2);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn keys(k: &[KeyCode]) -> HashSet<KeyCode> {
        k.iter().copied().collect()
    }

    #[test]
    fn looking_at_inverts_forward() {
        for (yaw, pitch) in [(0.0, 0.0), (1.0, 0.3), (-2.5, -0.7), (3.0, 1.2)] {
            let w = Walker {
                eye: Vec3::new(1.0, 5.0, -2.0),
                yaw,
                pitch,
                speed: 5.0,
                walk: false,
            };
            let back = Walker::looking_at(w.eye, w.eye + w.forward() * 7.0, 5.0, 0.0);
            assert!((back.yaw - yaw).abs() < 1e-5, "{yaw} -> {}", back.yaw);
            assert!(
                (back.pitch - pitch).abs() < 1e-5,
                "{pitch} -> {}",
                back.pitch
            );
            assert!(!back.walk, "eye above walking height flies");
        }
        let w = Walker::looking_at(Vec3::new(0.0, EYE_HEIGHT, 0.0), Vec3::X, 1.0, 0.0);
        assert!(w.walk);
        let w = Walker::looking_at(Vec3::new(0.0, 10.0 + EYE_HEIGHT, 0.0), Vec3::X, 1.0, 10.0);
        assert!(w.walk, "on a hill 10 m up");
        // A degenerate target looks along −Z instead of producing NaN.
        let w = Walker::looking_at(Vec3::ONE, Vec3::ONE, 1.0, 0.0);
        assert!(w.yaw.abs() < 1e-6 && w.pitch.abs() < 1e-6);
    }

    #[test]
    fn walking_climbs_the_terrain_and_flying_stays_above_it() {
        // A slope rising 0.5 m per metre to the east.
        let hill = |x: f32, _z: f32| 0.5 * x.max(0.0);
        let mut w = Walker {
            eye: Vec3::new(0.0, EYE_HEIGHT, 0.0),
            yaw: std::f32::consts::FRAC_PI_2, // facing +X
            pitch: 0.0,
            speed: 2.0,
            walk: true,
        };
        w.step(&keys(&[KeyCode::KeyW]), 2.0, hill);
        assert!(
            (w.eye - Vec3::new(4.0, 2.0 + EYE_HEIGHT, 0.0)).length() < 1e-5,
            "{}",
            w.eye
        );
        w.walk = false;
        w.step(&keys(&[KeyCode::KeyQ]), 100.0, hill);
        assert!(
            (w.eye.y - (hill(w.eye.x, 0.0) + 0.2)).abs() < 1e-5,
            "{}",
            w.eye
        );
    }

    #[test]
    fn walking_follows_the_ground_and_flying_follows_the_view() {
        let flat = |_: f32, _: f32| 0.0;
        let mut w = Walker {
            eye: Vec3::new(0.0, EYE_HEIGHT, 0.0),
            yaw: std::f32::consts::FRAC_PI_2, // facing +X
            pitch: 0.5,
            speed: 2.0,
            walk: true,
        };
        w.step(&keys(&[KeyCode::KeyW, KeyCode::KeyE]), 0.5, flat);
        assert!(
            (w.eye - Vec3::new(1.0, EYE_HEIGHT, 0.0)).length() < 1e-5,
            "{}",
            w.eye
        );
        w.step(&keys(&[KeyCode::KeyD, KeyCode::ShiftLeft]), 0.25, flat);
        assert!(
            (w.eye - Vec3::new(1.0, EYE_HEIGHT, 2.0)).length() < 1e-5,
            "{}",
            w.eye
        );
        w.walk = false;
        let before = w.eye;
        w.step(&keys(&[KeyCode::KeyW]), 1.0, flat);
        let moved = w.eye - before;
        assert!((moved - w.forward() * 2.0).length() < 1e-5, "{moved}");
        w.step(&keys(&[KeyCode::KeyQ]), 100.0, flat);
        assert!((w.eye.y - 0.2).abs() < 1e-6, "never below 0.2 m: {}", w.eye);
        // Opposite keys cancel.
        let before = w.eye;
        w.step(&keys(&[KeyCode::KeyA, KeyCode::KeyD]), 1.0, flat);
        assert_eq!(w.eye, before);
    }
}
