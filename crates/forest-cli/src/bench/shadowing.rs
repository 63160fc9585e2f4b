//! Self-shadowing: the candidates for a crown's shadow on itself under any sun (none, the
//! opacity volume at three resolutions, per-vertex first-order spherical harmonics), each
//! against exact alpha-tested rays towards seeded random suns, with its bytes per model (see
//! `forest_bake::shadowing`). The renderers use the opacity volume; this suite is why.

use anyhow::Result;
use forest_bake::shadowing::{Candidate, measure};
use glam::Vec3;

use super::chart::{Chart, Series};
use super::report::Section;
use super::{Bench, Table};

/// Suns drawn per model (seeded): azimuth uniform, elevation stratified in 5°–90°.
const SUNS: u32 = 12;

/// The seeded suns: (azimuth, elevation) in degrees and the unit direction towards each.
/// Azimuths are uniform; elevations are uniform in 5°–90° and stratified (sun `k` of `n`
/// in the `k`-th of `n` equal bands), so that a few suns still span low and high ones.
pub fn seeded_suns(n: u32, seed: u64) -> Vec<(f32, f32, Vec3)> {
    let mut rng = forest_format::noise::SplitMix64(seed);
    (0..n)
        .map(|k| {
            let az = 360.0 * rng.next_f32();
            let el = 5.0 + 85.0 * (k as f32 + rng.next_f32()) / n as f32;
            (az, el, forest_format::shading::sun_direction(az, el))
        })
        .collect()
}

/// Run the suite.
pub fn run(b: &Bench) -> Result<Section> {
    if b.models.is_empty() {
        anyhow::bail!(
            "the shadowing suite traces the species' models: pass --models (none found under \
             assets/trees/)"
        );
    }
    let suns = seeded_suns(if b.quick { 3 } else { SUNS }, 29);
    let candidates = [
        Candidate::None,
        Candidate::Volume(16),
        Candidate::Volume(32),
        Candidate::Volume(64),
        Candidate::Harmonics,
    ];
    let mut table = Table::new(&[
        "species",
        "candidate",
        "bytes",
        "mean_abs_error",
        "mean_bias",
        "low_sun_abs_error",
    ]);
    let mut series: Vec<Series> = candidates
        .iter()
        .map(|c| Series {
            name: c.name(),
            line: false,
            ..Default::default()
        })
        .collect();
    let mut summary = Vec::new();
    for (path, model) in b.species_paths.iter().zip(&b.models) {
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().trim_end_matches(".atlas").to_string())
            .unwrap_or_default();
        let mesh = forest_bake::Mesh::load(model)?;
        let sphere = forest_bake::bounding_sphere(&mesh);
        let scene = forest_bake::trace::Scene::new(&mesh);
        let dirs: Vec<Vec3> = suns.iter().map(|s| s.2).collect();
        let errors = measure(&scene, &sphere, &dirs, &candidates);
        let vertices = mesh.tris.len() as u64 * 3;
        for (ci, e) in errors.iter().enumerate() {
            let mean = |v: &[f32]| v.iter().sum::<f32>() / v.len().max(1) as f32;
            let low: Vec<f32> = e
                .mae
                .iter()
                .zip(&suns)
                .filter(|(_, s)| s.1 < 25.0)
                .map(|(m, _)| *m)
                .collect();
            let (mae, bias) = (mean(&e.mae), mean(&e.bias));
            println!(
                "{name}, {}: {} bytes, mean |error| {mae:.4}, bias {bias:+.4}",
                e.candidate.name(),
                e.candidate.bytes(vertices)
            );
            for (m, s) in e.mae.iter().zip(&suns) {
                series[ci].points.push((f64::from(s.1), f64::from(*m)));
            }
            table.push(vec![
                name.clone(),
                e.candidate.name(),
                e.candidate.bytes(vertices).to_string(),
                format!("{mae:.5}"),
                format!("{bias:+.5}"),
                if low.is_empty() {
                    "-".into()
                } else {
                    format!("{:.5}", mean(&low))
                },
            ]);
            summary.push((name.clone(), e.candidate, mae));
        }
    }
    b.write("shadowing.csv", &table.csv())?;
    b.chart(
        "shadowing",
        &Chart {
            title: "Self-shadowing: error of each candidate against traced rays".into(),
            x_label: "sun elevation (degrees)".into(),
            y_label: "mean |visibility error| per triangle".into(),
            series,
            ..Default::default()
        },
    )?;
    let ratio = |c: Candidate| {
        let pick = |k: Candidate| {
            summary
                .iter()
                .filter(|s| s.1 == k)
                .map(|s| s.2)
                .sum::<f32>()
        };
        pick(c) / pick(Candidate::None).max(1e-9)
    };
    let text = format!(
        "Sun visibility of each model's own surface, per triangle (area-weighted, opaque \
         texels only), predicted by each candidate and compared with exact alpha-tested rays \
         towards {} seeded suns (azimuth uniform, elevation stratified uniformly in 5°–90°; seed 29). \
         Bytes are per model: one per voxel for the volumes, 4 half floats per vertex for \
         the harmonics (evaluated at the sample points themselves, a lower bound on their \
         error stored per vertex; the slab texels would need 4 more channels on top). Summed over the \
         species, the 32³ volume leaves {:.0} % of the error of no self-shadowing, 16³ {:.0} \
         %, 64³ {:.0} %, and the harmonics {:.0} %. The renderers use the 32³ \
         volume: one 32 KiB texture per species whatever the model's size, shared by every \
         method. `low_sun_abs_error` is over the suns below 25°.",
        suns.len(),
        100.0 * ratio(Candidate::Volume(32)),
        100.0 * ratio(Candidate::Volume(16)),
        100.0 * ratio(Candidate::Volume(64)),
        100.0 * ratio(Candidate::Harmonics),
    );
    Ok(Section {
        title: "Self-shadowing candidates".into(),
        text,
        table,
        charts: vec!["shadowing".into()],
    })
}
