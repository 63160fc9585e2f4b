//! What the viewer's G and Y keys step through: the wind's speeds and the seasons.

/// The wind speeds the G key steps through (m/s, mean): calm, light air, breeze, fresh
/// breeze, strong breeze, gale.
pub const WIND_STEPS: [f32; 6] = [0.0, 2.0, 5.0, 9.0, 13.0, 18.0];

/// The next wind speed of [`WIND_STEPS`] above (`up`) or below `speed`, staying at the ends.
pub fn wind_step(speed: f32, up: bool) -> f32 {
    if up {
        WIND_STEPS
            .into_iter()
            .find(|s| *s > speed + 1e-3)
            .unwrap_or(WIND_STEPS[WIND_STEPS.len() - 1].max(speed))
    } else {
        WIND_STEPS
            .into_iter()
            .rev()
            .find(|s| *s < speed - 1e-3)
            .unwrap_or(0.0)
    }
}

/// The seasons the Y key steps through: the models' own colours, then spring, summer, autumn
/// and late autumn.
pub const SEASON_STEPS: [Option<f32>; 5] =
    [None, Some(0.0), Some(1.0 / 3.0), Some(2.0 / 3.0), Some(1.0)];

/// The season after (`on`) or before `season` in [`SEASON_STEPS`], round the year: a season
/// between steps goes to the neighbouring step.
pub fn season_step(season: Option<f32>, on: bool) -> Option<f32> {
    let n = SEASON_STEPS.len();
    let key = |s: Option<f32>| s.map_or(-1.0, |v| v);
    let k = key(season);
    if on {
        SEASON_STEPS
            .into_iter()
            .find(|s| key(*s) > k + 1e-3)
            .unwrap_or(SEASON_STEPS[0])
    } else {
        SEASON_STEPS
            .into_iter()
            .rev()
            .find(|s| key(*s) < k - 1e-3)
            .unwrap_or(SEASON_STEPS[n - 1])
    }
}

/// How the HUD names a season.
pub fn season_name(season: Option<f32>) -> String {
    match season {
        None => "the models' own colours".into(),
        Some(s) => forest_format::colour::SEASONS
            .iter()
            .find(|(_, v)| (v - s).abs() < 1e-3)
            .map_or(format!("{s:.2}"), |(n, _)| (*n).to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_wind_key_steps_through_the_speeds_and_stops_at_the_ends() {
        let mut s = 0.0;
        let mut seen = vec![s];
        for _ in 0..WIND_STEPS.len() + 2 {
            s = wind_step(s, true);
            seen.push(s);
        }
        assert_eq!(&seen[..WIND_STEPS.len()], &WIND_STEPS);
        assert_eq!(s, WIND_STEPS[WIND_STEPS.len() - 1]);
        // A speed between steps goes to the neighbouring step; above the last it stays.
        assert_eq!(wind_step(6.0, true), 9.0);
        assert_eq!(wind_step(6.0, false), 5.0);
        assert_eq!(wind_step(30.0, true), 30.0);
        assert_eq!(wind_step(30.0, false), 18.0);
        assert_eq!(wind_step(0.0, false), 0.0);
    }

    #[test]
    fn the_season_key_goes_round_the_year() {
        let mut s = None;
        let mut seen = vec![s];
        for _ in 0..SEASON_STEPS.len() {
            s = season_step(s, true);
            seen.push(s);
        }
        assert_eq!(&seen[..SEASON_STEPS.len()], &SEASON_STEPS);
        assert_eq!(s, None);
        assert_eq!(season_step(None, false), Some(1.0));
        assert_eq!(season_step(Some(0.5), true), Some(2.0 / 3.0));
        assert_eq!(season_step(Some(0.5), false), Some(1.0 / 3.0));
        assert_eq!(season_step(Some(0.0), false), None);
        assert_eq!(season_name(Some(2.0 / 3.0)), "autumn");
        assert_eq!(season_name(Some(0.5)), "0.50");
    }
}
