//! Bevy's light, exposure and fog as the forest's run-time light ([`Lighting`]) and haze
//! ([`Atmosphere`]). Pure functions of plain numbers, so they are tested without a GPU.
//!
//! Bevy's PBR shades a diffuse surface of albedo `a` under a directional light of colour `c`
//! and illuminance `E` (lux) as `a/π · c·E · max(n·l, 0)`, adds `a · c_amb · B` for an ambient
//! light of colour `c_amb` and brightness `B` (cd/m²), and scales the sum by the camera's
//! exposure. The forest shades `a · (sun · max(n·l, 0) + sky/ground mix) · exposure`
//! ([`Lighting::shade`]), so the sun is `c·E/π`, the sky and ground both `c_amb · B` (Bevy's
//! ambient light is uniform), and the exposure is the camera's.

use bevy::math::Vec3;
use forest_format::shading::Lighting;
use forest_render::options::{Atmosphere, KOSCHMIEDER};

/// A Bevy vector as the forest crates' (Bevy and `forest-render` may use different glam
/// releases).
pub fn to_forest(v: Vec3) -> glam::Vec3 {
    glam::Vec3::from_array(v.to_array())
}

/// A Bevy matrix as the forest crates' (see [`to_forest`]).
pub fn mat_to_forest(m: bevy::math::Mat4) -> glam::Mat4 {
    glam::Mat4::from_cols_array(&m.to_cols_array())
}

/// A directional light as Bevy describes it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sun {
    /// Unit vector towards the light (Bevy lights shine along their local −Z, so this is the
    /// light's +Z axis in the forest's frame).
    pub to_light: Vec3,
    /// Linear RGB colour.
    pub colour: Vec3,
    /// Illuminance, lux.
    pub illuminance: f32,
}

/// The forest's light from Bevy's directional light (none: a sun of zero irradiance straight
/// above), ambient light (linear colour × brightness, cd/m²) and camera exposure (the
/// multiplier, `Exposure::exposure()`).
pub fn lighting(sun: Option<Sun>, ambient: Vec3, exposure: f32) -> Lighting {
    let (sun_dir, sun) = match sun {
        Some(s) if s.to_light.length_squared() > 0.0 && s.to_light.is_finite() => (
            s.to_light.normalize(),
            (s.colour * s.illuminance / std::f32::consts::PI).max(Vec3::ZERO),
        ),
        _ => (Vec3::Y, Vec3::ZERO),
    };
    let ambient = if ambient.is_finite() {
        ambient.max(Vec3::ZERO)
    } else {
        Vec3::ZERO
    };
    Lighting {
        sun_dir: to_forest(sun_dir),
        sun: to_forest(sun),
        sky: to_forest(ambient),
        ground: to_forest(ambient),
        exposure: if exposure.is_finite() && exposure > 0.0 {
            exposure
        } else {
            1.0
        },
    }
}

/// How Bevy's `DistanceFog` thins with distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Falloff {
    /// Fog from `start` to `end` metres, linear in between.
    Linear {
        /// Where the fog starts (m).
        start: f32,
        /// Where it is opaque (m).
        end: f32,
    },
    /// Transmittance `exp(−density · d)`.
    Exponential {
        /// Per metre.
        density: f32,
    },
    /// Transmittance `exp(−(density · d)²)`.
    ExponentialSquared {
        /// Per metre.
        density: f32,
    },
    /// Transmittance `exp(−extinction · d)` per channel.
    Atmospheric {
        /// Per metre, linear RGB.
        extinction: Vec3,
    },
}

/// The forest's haze for a Bevy fog of linear `colour` and `falloff` under the sky
/// irradiance `sky` (the [`lighting`]'s, from Bevy's ambient light): homogeneous (Bevy's
/// distance fog does not thin with height), with the visibility at which Bevy's fog leaves
/// 2 % of a surface's contrast (Koschmieder's 3.912 optical depths). The forest's haze is
/// exponential in distance, so Bevy's other falloffs match at that distance only.
///
/// Bevy mixes its fog colour into the exposed colour as it is; the forest tints its horizon
/// colour by the frame's sky irradiance over the default light's (so that a sinking sun dims
/// the haze) and scales it by the `exposure` as every radiance, so the horizon given here
/// is the fog colour divided by that tint and that exposure. No fog: clear air.
pub fn atmosphere(fog: Option<(Vec3, Falloff)>, sky: Vec3, exposure: f32) -> Atmosphere {
    let Some((colour, falloff)) = fog else {
        return Atmosphere {
            sun_disc: false,
            ..Atmosphere::CLEAR
        };
    };
    let visibility = match falloff {
        Falloff::Linear { start, end } => start + (end - start) * (1.0 - 0.02),
        Falloff::Exponential { density } => KOSCHMIEDER / density,
        Falloff::ExponentialSquared { density } => KOSCHMIEDER.sqrt() / density,
        Falloff::Atmospheric { extinction } => KOSCHMIEDER / extinction.element_sum() * 3.0,
    };
    let reference = Vec3::from_array(Lighting::default().sky.to_array());
    let tint = if sky.is_finite() {
        sky.max(Vec3::splat(1e-6))
    } else {
        reference
    };
    let exposure = if exposure.is_finite() && exposure > 0.0 {
        exposure
    } else {
        1.0
    };
    let colour = (colour.max(Vec3::ZERO) * reference / tint / exposure).to_array();
    Atmosphere {
        visibility: if visibility.is_finite() && visibility > 0.0 {
            visibility
        } else {
            f32::INFINITY
        },
        haze_height: f32::INFINITY,
        horizon: colour,
        zenith: colour,
        sun_disc: false,
    }
}

/// `wind` (in Bevy's world) as a forest placed by `forest_from_world` feels it: its direction
/// turned into the forest's space (its azimuth measured there), speed, gustiness and time as
/// they are. A direction the transform makes vertical keeps its azimuth.
pub fn wind_in_forest(
    wind: forest_format::wind::Wind,
    forest_from_world: bevy::math::Mat4,
) -> forest_format::wind::Wind {
    let d = wind.direction();
    let turned = forest_from_world.transform_vector3(Vec3::new(d.x, 0.0, d.y));
    if turned.x.hypot(turned.z) < 1e-6 {
        return wind;
    }
    forest_format::wind::Wind {
        towards_deg: turned.x.atan2(turned.z).to_degrees(),
        ..wind
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A surface facing the sun under Bevy's units shades as Bevy's Lambert term does.
    #[test]
    fn a_lit_surface_matches_bevys_lambert_term() {
        let sun = Sun {
            to_light: Vec3::new(0.0, 2.0, 0.0),
            colour: Vec3::new(1.0, 0.5, 0.25),
            illuminance: 10_000.0,
        };
        let exposure = 1.0 / (2f32.powf(9.7) * 1.2);
        let l = lighting(Some(sun), Vec3::ZERO, exposure);
        let albedo = Vec3::new(0.3, 0.6, 0.2);
        let forest = l.shade(to_forest(albedo), glam::Vec3::Y, 1.0, 1.0, 0.0);
        let bevy =
            to_forest(albedo / std::f32::consts::PI * sun.colour * sun.illuminance * exposure);
        assert!(
            (forest - bevy).abs().max_element() < 1e-5,
            "{forest} vs {bevy}"
        );
        // Facing away, only the (zero) ambient light: black.
        assert_eq!(
            l.shade(to_forest(albedo), -glam::Vec3::Y, 1.0, 1.0, 0.0),
            glam::Vec3::ZERO
        );
        assert!(l.validate().is_ok());
    }

    /// Ambient light alone: `albedo · colour · brightness` whatever the normal.
    #[test]
    fn ambient_light_is_uniform() {
        let l = lighting(None, Vec3::splat(80.0), 0.5);
        for n in [glam::Vec3::Y, -glam::Vec3::Y, glam::Vec3::X] {
            let c = l.shade(glam::Vec3::splat(0.5), n, 1.0, 1.0, 0.0);
            assert!(
                (c - glam::Vec3::splat(20.0)).abs().max_element() < 1e-4,
                "{c}"
            );
        }
        // Bad numbers never reach the GPU.
        let bad = lighting(None, Vec3::splat(f32::NAN), f32::NAN);
        assert!(bad.validate().is_ok());
    }

    /// Each falloff leaves 2 % contrast at the visibility it is given, and the haze's colour,
    /// once the forest tints it by the sky (`sky_tint` in environment.wgsl), is Bevy's fog
    /// colour whatever Bevy's light units and exposure.
    #[test]
    fn fog_visibility_leaves_two_percent() {
        let colour = Vec3::new(0.5, 0.6, 0.7);
        let sky = Vec3::new(800.0, 1000.0, 1500.0);
        let exposure = 0.25;
        let fog = |falloff| atmosphere(Some((colour, falloff)), sky, exposure);
        let exp = fog(Falloff::Exponential { density: 0.01 });
        assert!(((-0.01 * exp.visibility).exp() - 0.02).abs() < 1e-4);
        let sq = fog(Falloff::ExponentialSquared { density: 0.01 });
        assert!(((-(0.01 * sq.visibility).powi(2)).exp() - 0.02).abs() < 1e-4);
        let lin = fog(Falloff::Linear {
            start: 10.0,
            end: 110.0,
        });
        assert!((1.0 - (lin.visibility - 10.0) / 100.0 - 0.02).abs() < 1e-4);
        assert_eq!(exp.haze_height, f32::INFINITY);
        let reference = Vec3::from_array(Lighting::default().sky.to_array());
        let seen = Vec3::from_array(exp.horizon) * sky / reference * exposure;
        assert!((seen - colour).abs().max_element() < 1e-4, "{seen}");
        // No fog: no haze.
        assert_eq!(atmosphere(None, sky, 1.0).visibility, f32::INFINITY);
        // Degenerate fog or light: no NaN.
        assert_eq!(
            fog(Falloff::Exponential { density: 0.0 }).visibility,
            f32::INFINITY
        );
        let dark = atmosphere(
            Some((colour, Falloff::Exponential { density: 0.01 })),
            Vec3::ZERO,
            0.0,
        );
        assert!(dark.horizon.iter().all(|c| c.is_finite()));
    }

    /// A forest turned a quarter about +Y and moved feels the world's wind in its own space:
    /// the direction it feels, turned back into the world, is the wind's; speed, gusts and
    /// time unchanged.
    #[test]
    fn the_wind_turns_into_the_forests_space() {
        use forest_format::wind::Wind;
        let wind = Wind::new(90.0, 12.0).at(3.5);
        let world_from_forest = bevy::math::Mat4::from_rotation_translation(
            bevy::math::Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
            Vec3::new(100.0, 5.0, -40.0),
        );
        let felt = wind_in_forest(wind, world_from_forest.inverse());
        let d = felt.direction();
        let back = world_from_forest.transform_vector3(Vec3::new(d.x, 0.0, d.y));
        assert!((back - Vec3::X).length() < 1e-5, "{back}");
        assert_eq!(
            (felt.speed, felt.gustiness, felt.time),
            (12.0, wind.gustiness, 3.5)
        );
        // Unturned: the same azimuth.
        let same = wind_in_forest(wind, bevy::math::Mat4::from_translation(Vec3::ONE));
        assert!((same.towards_deg - 90.0).abs() < 1e-4);
    }
}
