//! `granbed-cli study element-time CHECKPOINT`: the time of one core per
//! element-step of the element loop on a bed's own state (issue #8), for
//! the scene's element (the one-point element, or F-bar).
//!
//! Reads a checkpoint of `granbed-cli bed`, then evaluates the internal
//! forces of every deformable granule (those the run evaluates; a granule
//! still rigid is skipped, as in the run) at the checkpoint's positions,
//! from its C_p⁻¹, on one thread, `--passes` times. Each pass starts from
//! the checkpoint's C_p⁻¹ again (copied outside the timed calls), so every
//! pass does the same work: the first step after the checkpoint's, with
//! the same elements yielding. Only the calls of
//! [`internal_forces_on`] are timed (the zeroing of the forces, the element
//! loop with its corrector and the assembly into the nodal forces), which
//! is what a profile of the run attributes to the element, and the median
//! pass is reported — a direct measure of the "ns per element-step per
//! core in the bed", without the sampling noise of a profile's shares.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context as _;
use clap::{Args, ValueEnum};
use granbed_kernel::element::batch::ElementPath;
use granbed_kernel::granule::forces::{ElementKind, internal_forces_on};

use crate::bed::checkpoint::Checkpoint;
use crate::bed::scene::Scene;
use crate::error::InputError;
use crate::output::Streams;

/// The element loop's code path ([`ElementPath`]).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum PathArg {
    /// The processor's fastest (AVX2 batches where available).
    Fastest,
    /// AVX2 batches (portable batches without AVX2).
    Avx2,
    /// Portable batches in the build's instruction set.
    Batched,
    /// Element by element.
    Scalar,
}

impl PathArg {
    fn path(self) -> ElementPath {
        match self {
            Self::Fastest => ElementPath::fastest(),
            Self::Avx2 => ElementPath::Avx2,
            Self::Batched => ElementPath::Batched,
            Self::Scalar => ElementPath::Scalar,
        }
    }
}

/// Options of `granbed-cli study element-time`.
#[derive(Args, Debug)]
pub struct ElementTimeArgs {
    /// A bed run's directory holding `checkpoint.bin` (of `granbed-cli
    /// bed`, e.g. with `--stop-at-strain`).
    #[arg(value_name = "CHECKPOINT")]
    pub checkpoint: PathBuf,

    /// Timed passes over the bed, 1..=1000.
    #[arg(long, value_name = "N", default_value_t = 7, allow_negative_numbers = true,
          value_parser = crate::numbers::whole::<u32>(1, 1000))]
    pub passes: u32,

    /// The one-point element loop's code path (F-bar runs element by
    /// element).
    #[arg(long, value_enum, default_value = "fastest")]
    pub path: PathArg,
}

/// What the passes measured.
#[derive(Clone, Debug, PartialEq)]
pub struct ElementTime {
    /// The scene's element formulation.
    pub kind: ElementKind,
    /// Element-steps per pass (elements of the deformable granules).
    pub element_steps: usize,
    /// Elements that yielded, in each pass (every pass starts from the
    /// checkpoint's state, so these agree).
    pub plastic_elements: Vec<usize>,
    /// Wall time of each pass's timed calls, s, in pass order.
    pub pass_seconds: Vec<f64>,
}

impl ElementTime {
    /// The median pass's ns per element-step (the upper median for an
    /// even count).
    pub fn median_ns(&self) -> f64 {
        let mut t = self.pass_seconds.clone();
        t.sort_by(f64::total_cmp);
        t[t.len() / 2] / self.element_steps as f64 * 1e9
    }

    /// The fastest pass's ns per element-step.
    pub fn min_ns(&self) -> f64 {
        let t = self
            .pass_seconds
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        t / self.element_steps as f64 * 1e9
    }
}

impl ElementTimeArgs {
    /// Runs the measurement and prints its table.
    pub fn run(&self, streams: &mut Streams<'_>) -> anyhow::Result<()> {
        if !(1..=1000).contains(&self.passes) {
            return Err(anyhow::Error::new(InputError(format!(
                "`--passes {}` is out of range (allowed: 1 to 1000)",
                self.passes
            ))));
        }
        let checkpoint = Checkpoint::read(&self.checkpoint)?;
        let t = measure(&checkpoint, self.passes, self.path.path())?;
        let strain = checkpoint.progress.samples.last().map_or(0.0, |s| s.strain);
        writeln!(
            streams.stdout,
            "strain,element,path,element_steps_per_pass,plastic_fraction,passes,\
             median_ns_per_element_step,min_ns_per_element_step"
        )?;
        // The F-bar element has one path, element by element.
        let (element, path) = match t.kind {
            ElementKind::OnePoint => ("one-point", self.path.path()),
            ElementKind::FBar => ("fbar", ElementPath::Scalar),
        };
        writeln!(
            streams.stdout,
            "{strain:.4},{element},{path:?},{},{:.4},{},{:.2},{:.2}",
            t.element_steps,
            t.plastic_elements[0] as f64 / t.element_steps as f64,
            t.pass_seconds.len(),
            t.median_ns(),
            t.min_ns()
        )?;
        Ok(())
    }
}

/// Times `passes` passes of the element loop (the one-point element's on
/// `path`) over the deformable granules of `checkpoint`.
pub fn measure(
    checkpoint: &Checkpoint,
    passes: u32,
    path: ElementPath,
) -> anyhow::Result<ElementTime> {
    let scene =
        Scene::from_toml(&checkpoint.progress.scene_toml).context("the checkpoint's scene")?;
    let material = scene.material()?;
    let mesh = scene.granule_mesh()?;
    let view = mesh.view();
    let settings = scene.element_settings()?;
    let granules: Vec<_> = checkpoint
        .state
        .granules
        .iter()
        .filter(|g| !g.rigid)
        .collect();
    if passes == 0 {
        anyhow::bail!("no passes to time (at least 1)");
    }
    if granules.is_empty() {
        anyhow::bail!(
            "every granule of the checkpoint is still rigid (untouched), so no element is \
             evaluated: take a later checkpoint"
        );
    }
    let nodes = view.mesh.positions.len();
    let points = view.mesh.hexes.len() * settings.points_per_element();
    for (i, g) in granules.iter().enumerate() {
        if g.x.len() != nodes || g.cp_inv.len() != points {
            anyhow::bail!("granule {i} of the checkpoint does not fit the scene's mesh");
        }
    }
    let mut cp_inv = vec![[0.0; 6]; points];
    let mut f = vec![[0.0; 3]; nodes];
    let mut plastic_elements = Vec::with_capacity(passes as usize);
    let mut pass_seconds = Vec::with_capacity(passes as usize);
    for _ in 0..passes {
        let (mut seconds, mut plastic) = (0.0, 0);
        for (i, g) in granules.iter().enumerate() {
            cp_inv.copy_from_slice(&g.cp_inv);
            let start = Instant::now();
            let summary =
                internal_forces_on(path, &view, &material, &settings, &g.x, &mut cp_inv, &mut f);
            seconds += start.elapsed().as_secs_f64();
            let summary = summary.with_context(|| format!("deformable granule {i}"))?;
            plastic += summary.plastic_elements;
        }
        pass_seconds.push(seconds);
        plastic_elements.push(plastic);
    }
    Ok(ElementTime {
        kind: settings.kind,
        element_steps: granules.len() * view.mesh.hexes.len(),
        plastic_elements,
        pass_seconds,
    })
}
