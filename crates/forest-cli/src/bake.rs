//! `forest bake` and `forest info`.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::Args;
use forest_format::{Atlas, BakeParams, ColourEncoding};

/// Arguments of `forest bake`.
#[derive(Args, Debug)]
pub struct BakeArgs {
    /// The tree model: an OBJ file with its MTL and textures beside it, or glTF 2.0 (`.gltf`,
    /// `.glb`).
    pub model: PathBuf,
    /// Output atlas folder (conventionally NAME.atlas); an existing atlas there is replaced.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Sampling directions over the upper hemisphere (horizon to zenith).
    #[arg(long, default_value_t = 15, allow_negative_numbers = true)]
    pub directions: u32,
    /// Sampling directions below the horizon, for trees seen from below (walkthroughs): a ring
    /// at −45° and the nadir at the default 5; 0 clamps views from below onto the horizon.
    #[arg(long, default_value_t = 5, allow_negative_numbers = true)]
    pub below: u32,
    /// How quad planes are fitted: gap-aware (no plane bridges a depth gap) or least-squares
    /// (the paper's fit over all of a quad's pixels).
    #[arg(long, default_value = "gap-aware", value_parser = ["gap-aware", "least-squares"])]
    pub plane_fit: String,
    /// Parallel slabs per direction.
    #[arg(long, default_value_t = 2, allow_negative_numbers = true)]
    pub slabs: u32,
    /// Slab image side in pixels (a power of two).
    #[arg(long, default_value_t = 512, allow_negative_numbers = true)]
    pub resolution: u32,
    /// Smallest quad side in pixels (a power of two below the resolution).
    #[arg(long, default_value_t = 4, allow_negative_numbers = true)]
    pub min_quad: u32,
    /// Jittered samples per pixel.
    #[arg(long, default_value_t = 4, allow_negative_numbers = true)]
    pub spp: u32,
    /// Refused: atlases store no light since format 3. The sun is chosen at run time
    /// (`forest render --sun AZ,EL`, `forest view`, every bench).
    #[arg(long, hide = true, allow_hyphen_values = true)]
    pub sun: Option<String>,
    /// JPEG quality of the colour mosaic (1–100).
    #[arg(
        long,
        default_value_t = 80,
        conflicts_with = "lossless",
        allow_negative_numbers = true
    )]
    pub quality: u8,
    /// Store colour losslessly (PNG) instead of JPEG.
    #[arg(long)]
    pub lossless: bool,
    /// Also write every slab image side by side to this PNG.
    #[arg(long, value_name = "PNG")]
    pub contact_sheet: Option<PathBuf>,
    /// Also write per-pixel depth and coverage of every slab image to this EXR.
    #[arg(long, value_name = "EXR")]
    pub depth_exr: Option<PathBuf>,
    /// Print one JSON line of figures instead of the human summary.
    #[arg(long)]
    pub json: bool,
    /// Refuse bakes whose estimated peak memory exceeds this many GiB (default: the memory
    /// the system reports available).
    #[arg(long, value_name = "GIB", allow_negative_numbers = true)]
    pub memory_limit: Option<f64>,
    /// Do not measure the hybrid method's switch distance. By default the bake renders the
    /// new atlas against its model on the GPU (views of one tree at 400×300) to find where
    /// the quad stream becomes as accurate as the triangles (within --switch-tolerance), and
    /// records it in the manifest; without it (or without a GPU) the hybrid switches where
    /// the finest quads project to 1.5 pixels.
    #[arg(long)]
    pub no_hybrid_switch: bool,
    /// The hybrid switch's tolerance: the quad stream may be up to this fraction less
    /// accurate (mean FLIP) than the model's triangles where the hybrid switches a tree to
    /// it (0: as accurate; 0 to 10).
    #[arg(long, default_value_t = forest_measure::switch::DEFAULT_TOLERANCE, value_parser = parse_tolerance, allow_negative_numbers = true)]
    pub switch_tolerance: f32,
    /// Do not store the prepared model (model.bin: the model's triangles with their traced
    /// sky visibility, its mesh LODs and billboards) in the atlas. The geometry methods and
    /// the hybrid then need the model itself (`forest render --models`), and the Bevy plugin
    /// offers the quad stream and impostors only.
    #[arg(long)]
    pub no_model: bool,
}

/// Arguments of `forest info`.
#[derive(Args, Debug)]
pub struct InfoArgs {
    /// Atlas folder.
    pub atlas: PathBuf,
    /// Print the figures as one JSON line.
    #[arg(long)]
    pub json: bool,
}

impl BakeArgs {
    fn params(&self) -> BakeParams {
        BakeParams {
            directions: self.directions,
            below: self.below,
            plane_fit: if self.plane_fit == "least-squares" {
                forest_format::PlaneFit::LeastSquares
            } else {
                forest_format::PlaneFit::GapAware
            },
            slabs: self.slabs,
            resolution: self.resolution,
            min_quad: self.min_quad,
            spp: self.spp,
            colour: if self.lossless {
                ColourEncoding::Png
            } else {
                ColourEncoding::Jpeg {
                    quality: self.quality,
                }
            },
        }
    }
}

/// Refuse outputs that cannot be written before spending time on the bake.
fn check_output_file(path: &Path, what: &str) -> Result<()> {
    let parent = path.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(p) = parent
        && !p.is_dir()
    {
        bail!(
            "{what} {}: folder {} does not exist",
            path.display(),
            p.display()
        );
    }
    if path.is_dir() {
        bail!("{what} {} is a folder", path.display());
    }
    Ok(())
}

/// Memory the system reports available (`MemAvailable` in /proc/meminfo), where it says.
fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// Peak resident memory of this process so far (`VmHWM`), where the system says.
fn peak_resident() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = text.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// Run `forest bake`.
pub fn run(args: &BakeArgs) -> Result<()> {
    let params = args.params();
    params.validate()?;
    let need = check(args, &params)?;
    let bar = crate::progress::bar(
        format!("tracing {}", args.model.display()),
        "tiles",
        args.json,
    );
    let progress = |done: u64, total: u64| {
        bar.set_length(total);
        bar.set_position(done);
    };
    let mut out = forest_bake::bake_file(&args.model, &params, &progress)?;
    bar.finish_and_clear();

    // The model prepared for the geometry methods (stored, and drawn by the switch
    // measurement), reusing the bake's traced sky visibility.
    let model = if args.no_model && args.no_hybrid_switch {
        None
    } else {
        let mesh = forest_bake::Mesh::load(&args.model)?;
        let sky = std::mem::take(&mut out.sky);
        let same = out.atlas.manifest.source.hash == format!("{:016x}", mesh.hash);
        let sky = same.then_some(&sky[..]);
        Some(std::sync::Arc::new(forest_bake::model::prepare(&mesh, sky)))
    };

    let (measured, switch_note) = measure_switch(args, &mut out, model.clone())?;
    let model_file = model.filter(|_| !args.no_model).map(|m| m.encode());
    let disk = out
        .atlas
        .save_with_model(&args.output, model_file.as_deref())?;
    if let Some(p) = &args.contact_sheet {
        // The sheet shows what was stored (after the lossy colour codec), not the raw trace.
        let layers = out
            .atlas
            .decode_layers(&args.output)
            .context("decoding the atlas just written")?;
        forest_bake::contact_sheet::write(p, &layers, params.mosaic_columns())?;
    }
    if let Some(p) = &args.depth_exr {
        forest_bake::write_depth_exr(p, &out)?;
    }

    let m = &out.atlas.manifest;
    // Each file's bytes, for the report and the summary (the nodes are encoded to count them).
    let mut files = out.atlas.file_bytes();
    if let Some(bytes) = &model_file {
        files.push((forest_format::model::MODEL_FILE, bytes.len() as u64));
    }
    let report = serde_json::json!({
        "model": args.model.display().to_string(),
        "output": args.output.display().to_string(),
        "triangles": out.triangles,
        "degenerate_triangles": m.source.degenerate_triangles,
        "seconds": (out.seconds * 1000.0).round() / 1000.0,
        "disk_bytes": disk,
        "peak_estimate_bytes": need,
        "peak_resident_bytes": peak_resident(),
        "colour_bytes": out.atlas.colour_file.len(),
        "alpha_bytes": out.atlas.alpha_file.len(),
        "gpu_bytes": m.gpu_bytes(),
        "layers": params.layers(),
        "resolution": params.resolution,
        "levels": m.levels,
        "nodes_per_level": m.nodes_per_level,
        "node_count": m.node_count,
        "bounding_radius": m.bounding_sphere.radius,
        "hybrid_switch": m.hybrid_switch,
        "files": files.iter().copied().collect::<std::collections::BTreeMap<_, _>>(),
        "hybrid_switch_ladder": measured
            .iter()
            .flat_map(|m| &m.ladder)
            .map(|r| serde_json::json!({
                "crown_radii": r.radii,
                "flip_geometry": r.geometry,
                "flip_quads": r.quads,
                "flip_lods": r.lods,
            }))
            .collect::<Vec<_>>(),
    });
    for note in out.notes.iter().chain(&switch_note) {
        eprintln!("forest: note: {note}");
    }
    if args.json {
        println!("{report}");
    } else {
        summary(args, &out, &params, disk, &files, measured.as_ref());
    }
    Ok(())
}

/// Refuse what the bake cannot do before tracing: a sun, an output that is not an atlas, a
/// folder that does not exist, more memory than there is, outputs over the model's own files
/// or each other. The bake's estimated peak, in bytes.
fn check(args: &BakeArgs, params: &forest_format::BakeParams) -> Result<u64> {
    if let Some(sun) = &args.sun {
        bail!(
            "--sun {sun}: atlases store no light since format 3, so the bake takes no sun; \
             choose it at run time: `forest render --sun AZ,EL`, `forest view --sun AZ,EL`"
        );
    }
    if args.output.exists()
        && !args
            .output
            .join(forest_format::atlas::MANIFEST_FILE)
            .is_file()
    {
        bail!(
            "{} exists and is not an atlas folder: refusing to overwrite it",
            args.output.display()
        );
    }
    forest_format::atlas::check_only_atlas_files(&args.output)?;
    let out_parent = args.output.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(p) = out_parent
        && !p.is_dir()
    {
        if p.exists() {
            bail!(
                "{} is a file, not a folder: the output atlas {} cannot be made in it",
                p.display(),
                args.output.display()
            );
        }
        bail!("output folder {} does not exist", p.display());
    }
    // Refuse what cannot fit before tracing for minutes and then failing an allocation.
    let model_bytes = std::fs::metadata(&args.model).map(|m| m.len()).unwrap_or(0);
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get() as u64);
    let mut need = forest_bake::peak_bytes_estimate(params, model_bytes, threads);
    if !args.no_hybrid_switch {
        // The atlas stays in memory while the switch is measured.
        need += forest_measure::switch::peak_bytes_estimate(model_bytes);
    }
    let limit = match args.memory_limit {
        Some(g) if g.is_finite() && g > 0.0 => Some((g * f64::from(1u32 << 30)) as u64),
        Some(g) => bail!("memory limit {g} GiB must be positive"),
        None => available_memory(),
    };
    if let Some(limit) = limit
        && need > limit
    {
        let gib = |b: u64| b as f64 / f64::from(1u32 << 30);
        bail!(
            "this bake needs about {:.1} GiB at its peak ({} layers of {}x{} px), more than the \
             {:.1} GiB available: lower --resolution or --directions/--below/--slabs",
            gib(need),
            params.layers(),
            params.resolution,
            params.resolution,
            gib(limit)
        );
    }
    // The model's own files (OBJ, material libraries, textures) are never overwritten, and
    // the outputs never overwrite each other.
    let inputs = forest_bake::source_files(&args.model)?;
    crate::guard::not_an_input(&args.output, "output atlas", &inputs)?;
    // An atlas is rebaked in place, but never inside another atlas.
    if let Some(parent) = args.output.parent().filter(|p| !p.as_os_str().is_empty()) {
        crate::guard::not_in_atlas(parent, "output atlas's folder")?;
    }
    if let Some(p) = &args.contact_sheet {
        crate::guard::output(p, "contact sheet", &inputs)?;
        crate::guard::apart_from(p, "contact sheet", &args.output, "output atlas")?;
        crate::guard::extension(p, "contact sheet", "PNG", &["png"])?;
        check_output_file(p, "contact sheet")?;
    }
    if let Some(p) = &args.depth_exr {
        crate::guard::output(p, "depth EXR", &inputs)?;
        crate::guard::apart_from(p, "depth EXR", &args.output, "output atlas")?;
        if let Some(c) = &args.contact_sheet {
            crate::guard::apart_from(p, "depth EXR", c, "contact sheet")?;
        }
        crate::guard::extension(p, "depth EXR", "OpenEXR", &["exr"])?;
        check_output_file(p, "depth EXR")?;
    }
    Ok(need)
}

/// Where the hybrid should switch this model to the quad stream, measured before the atlas
/// is written (so that it is written once, whole) and stored in its manifest; a note instead
/// when there is no GPU.
fn measure_switch(
    args: &BakeArgs,
    out: &mut forest_bake::BakeOutput,
    model: Option<std::sync::Arc<forest_format::model::PreparedModel>>,
) -> Result<(Option<forest_measure::switch::Measured>, Option<String>)> {
    let mut measured = None;
    let mut switch_note = None;
    if !args.no_hybrid_switch {
        match crate::gpu_context() {
            Ok(ctx) => {
                let bar =
                    crate::progress::bar("measuring the hybrid switch".into(), "views", args.json);
                let progress = |done: u64, total: u64| {
                    bar.set_length(total);
                    bar.set_position(done);
                };
                let species =
                    forest_render::scene::SpeciesData::decode(out.atlas.clone(), &args.output)?;
                let model = model.expect("prepared when the switch is measured");
                let m = forest_measure::switch::measure(
                    &ctx,
                    species,
                    model,
                    args.switch_tolerance,
                    crate::colour_format(),
                    &progress,
                )
                .context("measuring the hybrid switch (skip it with --no-hybrid-switch)")?;
                bar.finish_and_clear();
                out.atlas.manifest.hybrid_switch = Some(m.switch);
                measured = Some(m);
            }
            Err(e) => {
                switch_note = Some(format!(
                    "no GPU adapter ({e}): the hybrid switch was not measured, the hybrid \
                     switches where the finest quads project to {} px",
                    forest_render::DEFAULT_SWITCH_PIXELS
                ));
            }
        }
    }
    Ok((measured, switch_note))
}

/// The bake's summary in words.
fn summary(
    args: &BakeArgs,
    out: &forest_bake::BakeOutput,
    params: &forest_format::BakeParams,
    disk: u64,
    files: &[(&str, u64)],
    measured: Option<&forest_measure::switch::Measured>,
) {
    let m = &out.atlas.manifest;
    let mb = |b: u64| b as f64 / 1e6;
    println!(
        "baked {} -> {} in {:.1} s",
        args.model.display(),
        args.output.display(),
        out.seconds
    );
    println!(
        "  {} triangles ({} degenerate skipped), bounding radius {:.2} m",
        out.triangles, m.source.degenerate_triangles, m.bounding_sphere.radius
    );
    println!(
        "  {} + {} directions (above + below the horizon) x {} slabs of {}² px, {} levels \
         (smallest quad {} px), {} spp, {} plane fit",
        params.directions,
        params.below,
        params.slabs,
        params.resolution,
        m.levels,
        params.min_quad,
        params.spp,
        params.plane_fit.name()
    );
    println!(
        "  nodes per level {:?}, {} in all",
        m.nodes_per_level, m.node_count
    );
    println!(
        "  disk {:.2} MB ({}), GPU {:.2} MB (BC7 albedo and surface with mips, nodes, \
         opacity volume)",
        mb(disk),
        file_summary(files),
        mb(m.gpu_bytes())
    );
    if let Some(measured) = measured {
        println!(
            "  hybrid switch: {}",
            forest_measure::switch::describe_measured(measured)
        );
        println!(
            "  {}",
            forest_measure::switch::describe_lods(&measured.ladder, measured.switch.crown_radii)
        );
    }
    if let Some(p) = &args.contact_sheet {
        println!("  contact sheet {}", p.display());
    }
}

fn parse_tolerance(s: &str) -> Result<f32, String> {
    let max = forest_format::atlas::HybridSwitch::MAX_TOLERANCE;
    match s.parse::<f32>() {
        Ok(t) if (0.0..=max).contains(&t) => Ok(t),
        _ => Err(format!("{s:?}: expected a fraction from 0 to {max}")),
    }
}

/// Each file's megabytes, e.g. `colour.jpg 0.88, alpha.png 0.44, …`, from
/// [`Atlas::file_bytes`].
fn file_summary(files: &[(&str, u64)]) -> String {
    files
        .iter()
        .map(|(f, b)| format!("{f} {:.2}", *b as f64 / 1e6))
        .collect::<Vec<_>>()
        .join(", ")
}

/// What an atlas stores per texel and per model, in words.
fn channels(m: &forest_format::AtlasManifest) -> String {
    format!(
        "premultiplied albedo (sRGB) and coverage at {r}²; normal (hemispherical octahedral), \
         sky visibility and translucency at {s}², premultiplied, linear; an opacity volume of \
         {v}³ voxels (optical depth per voxel length up to {d:.3})",
        r = m.params.resolution,
        s = m.params.resolution / forest_format::atlas::SURFACE_SCALE,
        v = m.opacity.resolution,
        d = m.opacity.max_depth
    )
}

/// Run `forest info`.
pub fn info(args: &InfoArgs) -> Result<()> {
    let atlas = Atlas::load(&args.atlas)?;
    let m = &atlas.manifest;
    // The prepared model, checked as a renderer checks it.
    let model = forest_format::model::PreparedModel::load(&args.atlas)?;
    if let Some(model) = &model {
        model.check_atlas(&args.atlas, m)?;
    }
    let mut files = atlas.file_bytes();
    let model_path = args.atlas.join(forest_format::model::MODEL_FILE);
    if model.is_some() {
        let bytes = std::fs::metadata(&model_path)
            .with_context(|| model_path.display().to_string())?
            .len();
        files.push((forest_format::model::MODEL_FILE, bytes));
    }
    let lod_triangles = model.as_ref().map(|m| m.lod_vertices.map(|v| v / 3));
    if args.json {
        println!(
            "{}",
            serde_json::json!({
                "source": m.source,
                "params": m.params,
                "levels": m.levels,
                "nodes_per_level": m.nodes_per_level,
                "node_count": m.node_count,
                "gpu_bytes": m.gpu_bytes(),
                "files": files
                    .iter()
                    .copied()
                    .collect::<std::collections::BTreeMap<_, _>>(),
                "model_lod_triangles": lod_triangles,
                "channels": channels(m),
                "opacity": m.opacity,
                "bounding_sphere": m.bounding_sphere,
                "hybrid_switch": m.hybrid_switch,
            })
        );
    } else {
        println!(
            "{}: {} ({} triangles), {} + {} directions x {} slabs of {}² px, {} levels, {} nodes, GPU {:.2} MB",
            args.atlas.display(),
            m.source.file,
            m.source.triangles,
            m.params.directions,
            m.params.below,
            m.params.slabs,
            m.params.resolution,
            m.levels,
            m.node_count,
            m.gpu_bytes() as f64 / 1e6
        );
        println!("  files: {}", file_summary(&files));
        println!("  channels: {}", channels(m));
        match lod_triangles {
            Some([l0, l1, l2]) => println!(
                "  model (the geometry methods and the hybrid): {l0} triangles, mesh LODs \
                 {l1} and {l2}, {} billboards",
                forest_format::model::BILLBOARDS
            ),
            None => println!(
                "  model: none stored (baked with --no-model); the geometry methods and the \
                 hybrid need --models"
            ),
        }
        println!("  hybrid switch: {}", forest_measure::switch::describe(m));
    }
    Ok(())
}
