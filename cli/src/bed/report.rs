//! `report.html`: one page of a bed run: its warnings, the plots inline as
//! SVG (first: what a reader looks at), the section pictures of its
//! snapshots (as images of `vtk/section_<k>.svg`, too large to inline),
//! the summary table (the fields of `summary.json`, floats rounded to
//! [`crate::html::TABLE_DIGITS`], all their digits in the cell's title), and the scene
//! as TOML. All text is HTML-escaped.

use core::fmt::Write as _;
use std::path::Path;

use super::density_map::MAP_COLUMNS;
use super::network::{NETWORK_COLUMNS, network_file};
use super::outputs::{COMPRESSION_COLUMNS, Summary};
use super::scene::{DEFAULT_SCENE, Scene};
use super::snapshot_tables::{CONTACT_COLUMNS, GRANULE_COLUMNS, contacts_file, granules_file};
use super::snapshots::{PVD_FILE, VTK_DIR};
use super::stress_profile::{STRESS_COLUMNS, stress_file};
use crate::csv::Field;
use crate::html::{
    Row, figure, fit_cell, glossary, html_escape, key_table, kpa, num, page_head, picture,
    summary_rows, summary_table, warnings_section,
};
use crate::numbers::short;
use crate::output::write_text;

/// File name of the report in the output directory.
pub const REPORT_FILE: &str = "report.html";

/// The fields of `summary.json` shown first, in this order, with their
/// meaning; any other field follows (nested objects such as `kawakita` and
/// `heckel` are flattened to `kawakita.<field>`; the scene, `scene` and
/// `scene_toml`, is shown as TOML instead).
const FIELDS: [(&str, &str); 120] = [
    ("kawakita_a", "Kawakita a (limiting strain)"),
    ("kawakita_inv_b_pa", "Kawakita 1/b, Pa"),
    (
        "kawakita.r_squared",
        "R² of the Kawakita line P/C against P",
    ),
    ("kawakita.points", "output rows in the Kawakita fit"),
    (
        "kawakita.min_strain",
        "the Kawakita fit takes the rows with C ≥ this",
    ),
    (
        "heckel_yield_pressure_pa",
        "Heckel mean yield pressure P_y = 1/K, Pa",
    ),
    ("heckel.a", "Heckel intercept A of ln(1/(1 − D)) = K·P + A"),
    ("heckel.k_per_pa", "Heckel slope K, 1/Pa"),
    ("heckel.d_a", "D_A = 1 − exp(−A)"),
    (
        "heckel.d_b",
        "D_B = D_A − D0: the densification by rearrangement, beyond the fit's line",
    ),
    (
        "heckel.r_squared",
        "R² of the Heckel line ln(1/(1 − D)) against P",
    ),
    ("heckel.points", "output rows in the Heckel fit"),
    (
        "heckel.min_strain",
        "the Heckel fit takes the rows with C ≥ this",
    ),
    (
        "heckel_mean_pressure.yield_pressure_pa",
        "Heckel P_y on the mean of the two punches' pressures, Pa",
    ),
    (
        "heckel_mean_pressure.a",
        "its intercept A (the mean punch pressure)",
    ),
    ("heckel_mean_pressure.k_per_pa", "its slope K, 1/Pa"),
    ("heckel_mean_pressure.d_a", "its D_A = 1 − exp(−A)"),
    ("heckel_mean_pressure.d_b", "its D_B = D_A − D0"),
    ("heckel_mean_pressure.r_squared", "its R²"),
    ("heckel_mean_pressure.points", "output rows in that fit"),
    (
        "heckel_mean_pressure.min_strain",
        "that fit takes the rows with C ≥ this (as the Heckel fit)",
    ),
    (
        "initial_solid_fraction",
        "the poured bed's solid fraction D0 (solid volume / die volume below H0)",
    ),
    (
        "final_solid_fraction",
        "the bed's solid fraction D at the end, in the die under load",
    ),
    (
        "initial_packing_fraction",
        "the granules' packing fraction at C = 0: their envelope volume / die volume",
    ),
    (
        "final_packing_fraction",
        "the granules' packing fraction at the end (1 − it: the porosity between them)",
    ),
    (
        "quasi_static_strains",
        "the strains whose kinetic and force figures the certificate judged (the second half of the rows; --rate-check compares the curves from C = 0.02)",
    ),
    (
        "material.youngs_modulus_pa",
        "granule Young's modulus E, Pa",
    ),
    ("material.poisson_ratio", "granule Poisson's ratio ν"),
    ("material.yield_stress_pa", "granule yield stress σ_y, Pa"),
    ("material.eta0", "granule initial relative density η0"),
    ("material.cp", "yield-surface constant c_p"),
    ("material.eta_c", "critical relative density η_c"),
    ("material.true_density_kg_m3", "true (solid) density, kg/m³"),
    (
        "material.friction",
        "friction coefficient μ of every contact",
    ),
    (
        "yield_stress_pa",
        "granule yield stress, Pa (as material.yield_stress_pa)",
    ),
    (
        "eta0",
        "granule initial relative density η0 (as material.eta0)",
    ),
    ("final_strain", "axial strain reached"),
    (
        "final_pressure_pa",
        "upper-punch pressure at the end, Pa (averaged over the last output interval, at its mean strain final_die_wall.mean_strain)",
    ),
    (
        "final_relative_density",
        "mean granule relative density at the end",
    ),
    (
        "final_coordination",
        "coordination number Z at the end (granule contacts only; averaged over the last output interval)",
    ),
    (
        "final_die_wall.mean_strain",
        "mean strain of the last output interval, to which the die-wall figures belong",
    ),
    (
        "final_die_wall.pressure_pa",
        "radial pressure on the die wall beside the compact at the end, Pa",
    ),
    (
        "final_die_wall.mean_punch_pressure_pa",
        "mean of the two punches' pressures at the end, Pa: the compact's axial stress averaged over its height",
    ),
    (
        "final_die_wall.radial_to_axial",
        "die-wall pressure / mean punch pressure at the end: the radial-to-axial stress ratio K",
    ),
    (
        "final_die_wall.radial_to_upper",
        "die-wall pressure / upper-punch pressure at the end (the divisor of many instrumented-die studies)",
    ),
    (
        "final_die_wall.friction_to_normal",
        "|die-wall friction| / die-wall normal force at the end (Coulomb: at most μ)",
    ),
    (
        "unloading",
        "the upper punch's withdrawal after the final strain: none (scene unload = false, or the run did not reach its final strain)",
    ),
    (
        "unloading.rows",
        "rows of the upper punch's withdrawal after the final strain (unloading.csv)",
    ),
    (
        "unloading.from_strain",
        "strain the punch withdrew from (the loading's last row)",
    ),
    (
        "unloading.lift_off_strain",
        "strain where the punch came free (its force below 1 % of its largest)",
    ),
    (
        "unloading.elastic_recovery",
        "in-die elastic recovery (H_lift − H_min)/H_min",
    ),
    (
        "unloading.residual_die_wall_pressure_pa",
        "die-wall pressure at lift-off, Pa",
    ),
    (
        "unloading.residual_lower_pressure_pa",
        "lower-punch pressure at lift-off, Pa",
    ),
    (
        "unloading.loading_work_j",
        "the punches' work up to the final strain, J",
    ),
    (
        "unloading.returned_work_j",
        "work the bed gave back to the withdrawing punch (the elastic work), J",
    ),
    ("unloading.net_work_j", "loading work − work given back, J"),
    (
        "unloading.plasticity_factor",
        "plasticity factor net / (net + given back) (Stamm and Mathis)",
    ),
    (
        "unloading.elastic_energy_at_end_j",
        "granules' elastic energy at the final strain, J: the most the bed can give back",
    ),
    ("unloading.wall_time_s", "wall time of the withdrawal, s"),
    (
        "unloading.half_speed_elastic_recovery",
        "in-die elastic recovery of the same bed pressed and withdrawn at half the punch speed (--rate-check)",
    ),
    (
        "unloading.half_speed_plasticity_factor",
        "plasticity factor at half the punch speed",
    ),
    (
        "unloading.half_speed_recovery_change_rel",
        "|recovery at half speed − recovery| / recovery",
    ),
    (
        "unloading.half_speed_passed",
        "the unloading's rate check passed (the recovery's change below 0.05)",
    ),
    (
        "quasi_static.passed",
        "quasi-static certificate passed (every figure below its limit)",
    ),
    (
        "quasi_static.max_kinetic_to_internal",
        "largest kinetic energy / internal work over the judged rows (limit 0.01)",
    ),
    (
        "quasi_static.force_imbalance_rel",
        "mean |upper − lower − wall friction| / upper punch force (limit 0.05; the bed's \
         weight, which the lower punch carries too, counts in it: a few tenths of a per cent in \
         a small bed at low pressure)",
    ),
    (
        "quasi_static.rate_change_rel",
        "change of P(C) at half the punch speed (--rate-check; limit 0.05)",
    ),
    (
        "quasi_static.max_relative_kinetic_to_internal",
        "the kinetic ratio without the punches' imposed motion (not judged)",
    ),
    ("max_pressure_pa", "largest upper-punch pressure, Pa"),
    ("initial_bed_height_m", "initial bed height H0, m"),
    ("granules", "granules"),
    ("elements", "hexes in the bed"),
    ("steps", "time steps"),
    ("element_steps", "element evaluations"),
    ("wall_time_s", "wall time of the compression, s"),
    ("pour_wall_time_s", "wall time of the pour, s"),
    (
        "ns_per_element_step",
        "compression wall time per element evaluation, ns",
    ),
    (
        "contact_share",
        "share of the contact phase in the wall time",
    ),
    ("contact_sweeps_per_step", "contact sweeps per step"),
    (
        "face_list_builds_per_step",
        "face-list builds per step (pairs)",
    ),
    (
        "anchor_renewals_per_step",
        "face-list anchor renewals per step (granules)",
    ),
    (
        "pair_searches_per_step",
        "pair searches per step (all sweeps)",
    ),
    (
        "rigid_granule_step_share",
        "share of granule-steps taken as rigid bodies (untouched)",
    ),
    ("threads", "threads"),
    ("min_jacobian", "smallest element Jacobian ratio"),
    (
        "min_gauss_jacobian",
        "smallest Gauss-point Jacobian ratio at the output rows (≤ 0: folded)",
    ),
    (
        "max_penetration_m",
        "deepest granule overlap read by the contact detection, m",
    ),
    (
        "max_penetration_rel_element",
        "that overlap / the element size (accepted below 0.01)",
    ),
    (
        "final_hidden_overlap",
        "overlap by geometry at the end: not measured (a run stopped early)",
    ),
    (
        "final_hidden_overlap.depth_m",
        "deepest overlap measured by geometry at the end, m",
    ),
    (
        "final_hidden_overlap.rel_element",
        "that overlap / the element size (accepted below 0.01)",
    ),
    (
        "final_hidden_overlap.granule",
        "the granule whose surface node lies deepest in another",
    ),
    (
        "final_hidden_overlap.node",
        "that node, an index into the granule's nodes",
    ),
    (
        "final_hidden_overlap.inside_granule",
        "the granule it lies inside",
    ),
    (
        "final_hidden_overlap.wall_time_s",
        "wall time of that measurement, s (not in wall_time_s)",
    ),
    (
        "hourglass_to_internal",
        "hourglass energy / internal work (one-point element's spurious modes)",
    ),
    ("max_node_speed_ratio", "largest node speed / punch speed"),
    (
        "cost_figures_from_step",
        "first step the cost figures cover (0: the whole run)",
    ),
    ("interrupted", "stopped by SIGINT/SIGTERM (resumable)"),
    (
        "energy_residual_rel",
        "|energy ledger residual| / punch work",
    ),
    ("contact_loss_rel", "contact losses / punch work"),
    ("peak_memory_bytes", "peak resident memory, bytes"),
    (
        "added_mass.granules_scaled",
        "granules given heavier masses (variable mass scaling)",
    ),
    (
        "added_mass.max_factor",
        "largest factor on a granule's masses",
    ),
    (
        "added_mass.added_mass_rel",
        "mass added / the bed's mass before it",
    ),
    (
        "added_mass.undeformed_step_s",
        "stable step of the undeformed granule, s",
    ),
    ("error", "error that stopped the run early"),
    ("version", "granbed version"),
    ("format", "name of this file's format"),
    ("format_version", "version of this file's format"),
    // Shown in the fields above already, or above the table.
    ("kawakita.a", ""),
    ("kawakita.inv_b_pa", ""),
    ("heckel.yield_pressure_pa", ""),
    ("warnings", ""),
    // Their own table, "The fits by window".
    ("kawakita_windows", ""),
    ("heckel_windows", ""),
    // In the key results and the plot density_height.svg.
    ("final_density_by_height", ""),
    // Its own table, "The contact network".
    ("contact_network", ""),
    // Its own table, "The stress through the compact".
    ("stress_by_height", ""),
    // Its own table, "The density through the compact", and density_map.svg.
    ("final_density_map", ""),
];

/// The summary's fields as rows, in [`FIELDS`]' order, then the others;
/// the scene is shown as TOML below the table, not as rows.
fn rows(summary: &Summary<'_>) -> anyhow::Result<Vec<Row>> {
    // The density map has its own table and plot; its cells are no rows.
    summary_rows(summary, &FIELDS, |k| {
        k.starts_with("scene.") || k == "scene_toml" || k.starts_with("final_density_map.")
    })
}

/// The run's key figures as a short table with units, for the top of the
/// page (the full, unrounded set is the summary table below).
fn key_results(summary: &Summary<'_>) -> String {
    let k = &summary.kawakita;
    let rows = [
        (
            "Kawakita a (limiting strain; extrapolated past the strain reached)".to_owned(),
            num(summary.kawakita_a),
        ),
        (
            "Kawakita 1/b, kPa".to_owned(),
            kpa(summary.kawakita_inv_b_pa),
        ),
        (
            format!("Kawakita fit: rows with C ≥ {}, R²", short(k.min_strain)),
            format!("{} rows, {}", k.points, num(k.r_squared)),
        ),
        (
            "Heckel mean yield pressure P_y (upper punch, in the die), kPa".to_owned(),
            kpa(summary.heckel_yield_pressure_pa),
        ),
        (
            format!(
                "Heckel fit: rows with C ≥ {}, R²",
                short(summary.heckel.min_strain)
            ),
            format!(
                "{} rows, {}",
                summary.heckel.points,
                num(summary.heckel.r_squared)
            ),
        ),
        (
            "Heckel P_y on the mean punch pressure (P_upper + P_lower)/2, kPa".to_owned(),
            kpa(summary.heckel_mean_pressure.yield_pressure_pa),
        ),
        (
            "solid fraction D: poured (D0) → at the end, in the die".to_owned(),
            format!(
                "{} → {}",
                num(Some(summary.initial_solid_fraction)),
                num(Some(summary.final_solid_fraction))
            ),
        ),
        (
            "granules' packing fraction (their envelope volume / die volume): start → end"
                .to_owned(),
            format!(
                "{} → {}",
                num(Some(summary.initial_packing_fraction)),
                num(Some(summary.final_packing_fraction))
            ),
        ),
        (
            format!(
                "granules' mean relative density at the end in {} layers, bottom → top",
                super::outputs::DENSITY_LAYERS
            ),
            if summary.final_density_by_height.is_empty() {
                "n/a".to_owned()
            } else {
                summary
                    .final_density_by_height
                    .iter()
                    .map(|l| num(l.mean_relative_density))
                    .collect::<Vec<_>>()
                    .join(" → ")
            },
        ),
        (
            "upper-punch pressure at the end, kPa".to_owned(),
            kpa(Some(summary.final_pressure_pa)),
        ),
        (
            "die wall at the end: radial pressure σ_r, kPa; K = σ_r over the mean punch pressure \
             (that pressure in kPa); σ_r over the upper punch's; the wall's mobilised friction \
             |F_z|/F_n"
                .to_owned(),
            {
                let w = &summary.final_die_wall;
                format!(
                    "{}; {} (of {}); {}; {}",
                    kpa(w.pressure_pa),
                    num(w.radial_to_axial),
                    kpa(w.mean_punch_pressure_pa),
                    num(w.radial_to_upper),
                    num(w.friction_to_normal)
                )
            },
        ),
        (
            format!(
                "unloading: in-die elastic recovery (H_lift − H_min)/H_min, the punch free below \
                 {} % of its largest force; die-wall pressure left, kPa; work given back / the \
                 punch's work; plasticity factor (net / punch work)",
                100.0 * crate::bed::run::LIFT_OFF_FORCE_FRACTION
            ),
            match &summary.unloading {
                None => "n/a (scene unload = false, or the run did not reach its final strain)"
                    .to_owned(),
                Some(u) => format!(
                    "{}; {}; {} J / {} J; {}",
                    num(u.elastic_recovery),
                    kpa(u.residual_die_wall_pressure_pa),
                    num(u.returned_work_j),
                    num(Some(u.loading_work_j)),
                    num(u.plasticity_factor)
                ),
            },
        ),
        (
            "coordination number Z at the end (averaged over the last output interval)".to_owned(),
            num(Some(summary.final_coordination)),
        ),
        (
            "mean granule relative density at the end".to_owned(),
            num(Some(summary.final_relative_density)),
        ),
        (
            match summary.quasi_static_strains {
                Some([from, to]) => format!(
                    "quasi-static certificate (its kinetic and force figures judged over \
                     C = {} to {}, the second half of the rows)",
                    num(Some(from)),
                    num(Some(to))
                ),
                None => "quasi-static certificate".to_owned(),
            },
            if summary.quasi_static.passed {
                "passed".to_owned()
            } else {
                "NOT passed".to_owned()
            },
        ),
    ];
    key_table("Key results", &rows)
}

/// The Kawakita and Heckel fits over each window of
/// `summary.kawakita_windows` and `heckel_windows`: a, 1/b (kPa), P_y
/// (kPa) and the rows each fit took, a rejected fit marked as in the
/// series' tables, the run's own window named.
fn fits_by_window(summary: &Summary<'_>) -> String {
    let mut h = String::from(
        "<h3>The fits by window</h3>\n<p>The laws fitted again to the rows from several \
         strains on: their figures depend on the window, the more the earlier it starts \
         (rearrangement is not the laws' regime). The published scene fits C ≥ 0.25, as the \
         reference study did; ✗ marks a fit the summary would reject (its R² on hover); n/a: \
         no fit over the window (the run did not reach it, or its rows make no line).</p>\n\
         <table>\n<tr><th>rows fitted</th><th>Kawakita a</th><th>Kawakita 1/b, kPa</th>\
         <th>Heckel P_y, kPa</th><th>rows (Kawakita, Heckel)</th></tr>\n",
    );
    for (k, hk) in summary.kawakita_windows.iter().zip(&summary.heckel_windows) {
        let ok = super::outputs::kawakita_doubts(k).is_empty();
        let heckel_ok = hk.linear();
        let own = match (
            k.min_strain == summary.kawakita.min_strain,
            hk.min_strain == summary.heckel.min_strain,
        ) {
            (true, true) => " (the run's fits)",
            (true, false) => " (the run's Kawakita fit)",
            (false, true) => " (the run's Heckel fit)",
            (false, false) => "",
        };
        let _ = writeln!(
            h,
            "<tr><td>C ≥ {}{own}</td>{}{}{}<td class=\"num\">{}, {}</td></tr>",
            short(k.min_strain),
            fit_cell(k.a.map(|a| num(Some(a))), k.r_squared, ok),
            fit_cell(k.inv_b_pa.map(|b| kpa(Some(b))), k.r_squared, ok),
            fit_cell(
                hk.yield_pressure_pa.map(|p| kpa(Some(p))),
                hk.r_squared,
                heckel_ok
            ),
            k.points,
            hk.points
        );
    }
    h.push_str("</table>\n");
    h
}

/// The contact network at each snapshot (`summary.contact_network`):
/// one row per figure of [`NETWORK_COLUMNS`] (its meaning on hover), one
/// column per snapshot — the 16 figures as columns made a table about
/// 1650 px wide, cut off in a 960 px page and in print. Nothing if the run
/// has none.
fn contact_network(summary: &Summary<'_>) -> String {
    if summary.contact_network.is_empty() {
        return String::new();
    }
    let mut h = String::from(
        "<h3>The contact network</h3>\n<p>At each snapshot after a step (its nominal strain), \
         from its contacts table: granule–granule pairs only, the die and the punches left out \
         (vtk/network_&lt;k&gt;.csv; each column explained at the end of this page). f is a \
         pair's normal force and ⟨f⟩ their mean; a pair is strong if f &gt; ⟨f⟩ (the strong \
         network of granular mechanics). n is the direction of the pair's branch vector \
         between the granules' centres of mass, z the die axis: ⟨n_z²⟩ is 1/3 if the pairs \
         point in all directions alike (necessary for isotropy, not sufficient). In compressed \
         packings of rigid grains most pairs carry less than ⟨f⟩, the strong pairs align with \
         the compression and the weak ones lie across it (Radjai et al. 1998); the table shows \
         how far this bed follows. A pair slides as a whole when its friction reaches μ f.</p>\n\
         <table>\n<tr><th>figure</th>",
    );
    for s in &summary.contact_network {
        let _ = write!(h, "<th>snapshot {} (C = {:.3})</th>", s.snapshot, s.strain);
    }
    h.push_str("</tr>\n");
    let columns: Vec<_> = summary.contact_network.iter().map(|s| s.fields()).collect();
    for (i, (name, meaning)) in NETWORK_COLUMNS.iter().enumerate() {
        let _ = write!(h, "<tr><th title=\"{}\">{name}</th>", html_escape(meaning));
        for fields in &columns {
            let _ = write!(h, "<td class=\"num\">{}</td>", field_text(fields[i]));
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</table>\n");
    h
}

/// The stress through the compact at each snapshot
/// (`summary.stress_by_height`): per snapshot the walls' pressures and
/// the elements' mean stresses they must match, and Janssen's share of
/// the load beside the punches' (the layers themselves are in the files
/// and the plot). Nothing if the run has none.
fn stress_by_height(summary: &Summary<'_>) -> String {
    if summary.stress_by_height.is_empty() {
        return String::new();
    }
    let mut h = String::from(
        "<h3>The stress through the compact</h3>\n<p>At each snapshot after a step, from \
         its elements' stresses averaged over the compact between the punches (the room \
         between the granules counting unstressed: the powder's stress as a load cell reads \
         it; vtk/stress_&lt;k&gt;.csv has it in ten layers, plotted in stress_height.svg), \
         beside what the walls read in the same step. At rest the two must agree (the virial \
         theorem: ∫σ dV is the sum of x ⊗ f over the forces on the compact's boundary): the \
         mean lateral stress −(σ<sub>xx</sub> + σ<sub>yy</sub>)/2 is the die wall's pressure \
         F<sub>n</sub>/(2π R<sub>d</sub> H), and the mean axial stress lies between the \
         punches' pressures (the die wall's friction takes the load down from the upper \
         punch to the lower; the bed's weight adds its share downwards). K is the elements' \
         lateral over axial mean stress; Janssen's share exp(−4μK H/D) is what would reach \
         the lower punch if K were the same at every height and the wall's friction μ fully \
         mobilised. This K is the elements' in one step; the key results' K (summary.json's \
         final_die_wall) is the die wall's pressure over the mean punch pressure averaged over \
         the last output interval. The die wall's pressure leaves out the friction of the \
         punches' faces (2.5 % apart in the published scene at C = 0.3); the theorem's own \
         figure, −Σ (x f<sub>x</sub> + y f<sub>y</sub>)/2 over every wall force over the \
         compact's volume, has it (0.6 % apart there). What is left is the bed's inertia, its \
         damping and the element's hourglass forces, which vanish at rest.</p>\n<table>\n\
         <tr><th>C</th><th>H, mm</th><th>P_upper, kPa</th>\
         <th>P_lower, kPa</th><th>mean axial stress, kPa</th><th>die-wall pressure (wall \
         forces), kPa</th><th>mean lateral stress (elements), kPa</th><th>mean lateral stress \
         (all the walls' virial), kPa</th><th>K</th>\
         <th>P_lower / P_upper</th><th>Janssen's share</th><th>weight / die area, kPa</th>\
         </tr>\n",
    );
    for s in &summary.stress_by_height {
        let w = s.walls;
        let _ = writeln!(
            h,
            "<tr><td class=\"num\">{}</td><td class=\"num\">{}</td>{}<td class=\"num\">{}</td>\
             <td class=\"num\">{}</td><td class=\"num\">{}</td>\
             <td class=\"num\">{}</td></tr>",
            num(Some(s.strain)),
            num(Some(w.height_m * 1e3)),
            [
                w.upper_punch_pa,
                w.lower_punch_pa,
                s.mean_axial_stress_pa,
                w.die_wall_pa,
                s.mean_lateral_stress_pa,
                w.walls_lateral_pa,
            ]
            .map(|p| format!(
                "<td class=\"num\">{}</td>",
                kpa(Some(p).filter(|p| p.is_finite()))
            ))
            .concat(),
            num(Some(s.lateral_to_axial)),
            num(Some(s.lower_to_upper)),
            num(s.janssen_lower_to_upper),
            kpa(Some(w.weight_pa)),
        );
    }
    h.push_str("</table>\n");
    h
}

/// The density map of the last snapshot (`summary.final_density_map`)
/// as a table: the layers top first, the rings from the axis out, each
/// cell's solid fraction; and where it is densest and loosest. Nothing if
/// the run has none.
fn density_map(summary: &Summary<'_>) -> String {
    use super::density_map::{LAYERS, RINGS};
    let Some(s) = &summary.final_density_map else {
        return String::new();
    };
    let m = &s.map;
    // The cells' bounds are tenths and fifths.
    let span = |a: f64, b: f64| format!("{a:.1}–{b:.1}");
    let mut h = format!(
        "<h3>The density through the compact</h3>\n<p>The solid fraction at C = {} in the \
         compact's radial × height section (plots/density_map.svg draws it with the axial \
         stress; vtk/density_map_&lt;k&gt;.csv has every snapshot's): each cell's granule \
         solid over its volume, rows from the upper punch down, columns from the die's axis \
         out to its wall (r/R<sub>d</sub>). The ring at the wall is {} times as dense in its \
         upper half as in its lower half, the disc at the axis {} times (the tenths at the \
         punches are loose in any bed: spheres touch a flat punch at points). Densest cell: {} \
         (r/R<sub>d</sub> {}, z/H {}); loosest: {} (r/R<sub>d</sub> {}, z/H {}).\
         </p>\n<table>\n<tr><th>z/H \\ r/R<sub>d</sub></th>",
        num(Some(m.strain)),
        num(Some(s.wall_top_to_bottom).filter(|r| r.is_finite())),
        num(Some(s.axis_top_to_bottom).filter(|r| r.is_finite())),
        num(Some(s.densest.solid_fraction)),
        span(s.densest.inner, s.densest.outer),
        span(s.densest.bottom, s.densest.top),
        num(Some(s.loosest.solid_fraction)),
        span(s.loosest.inner, s.loosest.outer),
        span(s.loosest.bottom, s.loosest.top),
    );
    for r in 0..RINGS {
        let c = m.cell(r, 0);
        let _ = write!(h, "<th>{}</th>", span(c.inner, c.outer));
    }
    h.push_str("</tr>\n");
    for l in (0..LAYERS).rev() {
        let c = m.cell(0, l);
        let _ = write!(h, "<tr><td>{}</td>", span(c.bottom, c.top));
        for r in 0..RINGS {
            let _ = write!(
                h,
                "<td class=\"num\">{}</td>",
                num(Some(m.cell(r, l).solid_fraction))
            );
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</table>\n");
    h
}

/// A table cell's text: an integer as is, a float rounded as the report's
/// other figures ([`num`]).
fn field_text(cell: Field) -> String {
    match cell {
        Field::Int(n) => n.to_string(),
        Field::Real(x) => num(Some(x)),
        Field::Text(t) => t.to_owned(),
    }
}

/// The glossaries of the run's tables: `compression.csv` and the
/// snapshots' [`CONTACT_COLUMNS`] and [`GRANULE_COLUMNS`].
fn glossaries() -> String {
    let mut h = String::from("<h2>Columns of the tables</h2>\n");
    h.push_str(&glossary(
        "compression.csv",
        "One row per output interval; forces, pressures and Z are the interval's averages, \
         which belong to its mean strain (mean_strain, half an interval before the row's \
         strain); energies are the totals so far.",
        &COMPRESSION_COLUMNS,
    ));
    h.push_str(&glossary(
        "vtk/contacts_<k>.csv",
        "Beside snapshot k: one row per granule pair in contact in the snapshot's step, \
         ordered by the pair. The forces are the step's (the contacts are enforced anew each \
         step), not interval averages.",
        &CONTACT_COLUMNS,
    ));
    h.push_str(&glossary(
        "vtk/granules_<k>.csv",
        "Beside snapshot k: one row per granule.",
        &GRANULE_COLUMNS,
    ));
    h.push_str(&glossary(
        "vtk/network_<k>.csv",
        "Beside snapshot k: its contact network in figures, one row from contacts_<k>.csv \
         (the report's table \"The contact network\").",
        &NETWORK_COLUMNS,
    ));
    h.push_str(&glossary(
        "vtk/stress_<k>.csv",
        "Beside snapshot k: the stress through the compact, one row per layer of a tenth of \
         its height, bottom first, with the walls' readings in the snapshot's step repeated \
         on every row (the report's table \"The stress through the compact\").",
        &STRESS_COLUMNS,
    ));
    h.push_str(&glossary(
        "vtk/density_map_<k>.csv",
        "Beside snapshot k (the pour's too, at C = 0): the compact's radial × height \
         section, one row per cell, layers bottom first and within a layer the rings from the \
         die's axis out, with the compact's height and the die's radius repeated on every row \
         (the report's table \"The density through the compact\", plots/density_map.svg).",
        &MAP_COLUMNS,
    ));
    h
}

/// What the plot `name` (a file of `plots/`) shows and how it was made,
/// for its caption.
fn plot_caption(name: &str, summary: &Summary<'_>) -> Option<String> {
    let window = short;
    Some(match name {
        "pressure_strain.svg" => {
            "The punches' pressures against the axial strain C = (H0 − H)/H0: \
             force over the die's cross-section, averaged over each output interval and drawn \
             at the interval's mean strain. Early on \
             the lower punch carries the bed's weight and takes the impulses of its settling, so \
             its pressure lies above the upper one's; later the die wall's friction keeps it \
             below. Where the scene unloads, the upper punch then withdraws at the same speed \
             (unloading.csv) until its force falls below 1 % of its largest: the steep curve back \
             from the turn, below the loading curve (the work the bed dissipated it does not give \
             back)."
                .to_owned()
        }
        "kawakita.svg" => format!(
            "Kawakita's P/C against P (upper-punch pressure), C the interval's mean strain that \
             the averaged P belongs to; filled: the rows fitted (C ≥ {}), \
             rings: the others. The line's slope is 1/a and its intercept 1/(ab); a is the \
             limiting strain, extrapolated beyond the strain reached, and the fit depends on its \
             window (kawakita_min_strain). R² says how straight the line is, not how far another \
             pour of the same bed would move a and 1/b: on a 125-granule bed three pours spread \
             1/b by 78–148 % (BENCHMARKS.md); `granbed-cli bed --seeds 1,2,3` measures it for \
             this scene.",
            window(summary.kawakita.min_strain)
        ),
        "heckel.svg" => format!(
            "Heckel's ln(1/(1 − D)) against the upper-punch pressure P, with D the bed's solid \
             fraction in the die under load (the granules' solid over the die volume below the \
             upper punch) at each interval's mean strain, to which the averaged P belongs \
             (compression.csv's bed_solid_fraction is D at the row's end strain); filled: the rows \
             fitted (C ≥ {}). P_y = 1/K, the slope's inverse.",
            window(summary.heckel.min_strain)
        ),
        "coordination_strain.svg" => "The mean coordination number Z against the strain: \
             granule–granule contacts per granule, and with the die and punch contacts counted \
             too (the pairs touching in each step's first sweep, averaged over each output \
             interval); and at each snapshot after a step, from its contacts table (the pairs \
             that carried a force in the step, in any sweep), the whole bed's granule contacts \
             per granule (rings) and those of the bed's interior, the granules whose centres lie \
             at least a diameter from the die wall and both punches (dots; vtk/network_<k>.csv's \
             interior_coordination): a granule at a wall has fewer granule neighbours, so the \
             interior's Z is the one packing models such as Arzt's describe. The rings and the \
             dots count alike, so the gap between them is the walls'; the rings against the \
             curve show how the two ways of counting compare."
            .to_owned(),
        "relative_density_strain.svg" => "The granules' own relative density against the \
             strain (their solid over their volume, without the voids between them): the mean \
             of η0 V0/V over the granules, and the bed's total solid over the granules' total \
             volume."
            .to_owned(),
        "heywood_strain.svg" => "The Heywood shape coefficient α_SV = d S/V (6 for a sphere) \
             against the strain, with d the granule's volume-equivalent diameter d_V or its \
             nominal diameter: how far the granules flatten."
            .to_owned(),
        "solid_fraction_pressure.svg" => "The compaction profile: the bed's solid fraction D \
             (the granules' solid over the die volume below the upper punch) against the \
             upper-punch pressure P, D at each interval's mean strain, as in the Heckel plot."
            .to_owned(),
        "coordination_density.svg" => "The coordination number Z against the granules' \
             packing fraction (their envelope volume over the die volume below the upper punch: \
             D / relative_density_solid, the pores inside the granules left out), granule \
             contacts only and with the wall contacts: how the contact network grows as the bed \
             densifies, in the packing fraction Arzt's Z law for spheres is written in. Z is \
             averaged over each output interval, so D is taken at the interval's mean strain \
             (the granules' own density, which changes far more slowly, at the row)."
            .to_owned(),
        "density_height.svg" => format!(
            "Each granule's relative density where the run ended against the height of its \
             centre of mass in the compact (0: the lower punch, 1: the upper one), and the mean \
             over each fifth of the height (summary.json's final_density_by_height), at \
             C = {}. The die wall's friction holds back the load on its way down, so in a compact \
             pressed from above the granules at the bottom usually end less dense than those at \
             the top.",
            num(Some(summary.final_strain))
        ),
        "die_wall_strain.svg" => format!(
            "The die wall against the strain, at each output interval's mean strain, from where \
             the upper punch carries 5 % of its largest load (before, the bed's own weight is a \
             large part of the stresses): K = σ_r / ((P_upper + P_lower)/2), the radial stress \
             σ_r = F_n/(2π R_d H) (the wall's normal force over its area beside the compact of \
             height H) over the mean punch pressure, the compact's radial-to-axial stress ratio \
             averaged over its height (an instrumented die reads σ_r at one sensor and often \
             divides it by P_upper: summary.json's final_die_wall.radial_to_upper); and \
             |F_z|/F_n, the axial friction the wall holds over its normal force, which Coulomb's \
             law keeps at or below the friction coefficient μ = {} (the black dashed line) and which \
             reaches μ where every granule at the wall slides axially. The punches' forces \
             balance as F_upper + W = F_lower + F_z, W the bed's weight, so (F_upper − \
             F_lower)/F_n, the usual estimate from the punches, falls short of |F_z|/F_n by W/F_n.",
            summary
                .material
                .map_or("n/a".to_owned(), |m| num(Some(m.friction)))
        ),
        "stress_height.svg" => "The axial stress through the compact at each snapshot after a \
             step: each tenth of the compact's height, its elements' mean axial stress −σ_zz \
             over the whole layer (vtk/stress_<k>.csv) divided by the upper punch's pressure in \
             the same step, at the layer's mid-height (0: the lower punch, 1: the upper one). \
             The die wall's friction takes the load down on its way to the lower punch, so the \
             curves lean towards smaller stresses at the bottom; the layers at the punches hold \
             fewer granules (a flat punch leaves gaps between spheres). The dashed line is \
             Janssen's exp(−4μK (H − z)/D) for the last snapshot, from its K (the elements' \
             lateral over axial mean stress, table \"The stress through the compact\") and the \
             wall's friction coefficient μ: the fall if K were the same at every height and \
             every granule at the wall slid."
            .to_owned(),
        "density_map.svg" => "The compact's half-section at the last snapshot, between the \
             die's axis (left) and its wall (right, the thick line), the lower punch at the \
             bottom, drawn to scale: in rings of equal width and tenths of the height, the solid \
             fraction (the granules' solid over the cell's volume) and the mean axial stress \
             −σ_zz over the cell (vtk/density_map_<k>.csv; table \"The density through the \
             compact\"). Each panel is coloured from its smallest value (dark) to its largest \
             (yellow). The die wall's friction holds the load back, so a compact pressed from \
             above is usually densest at its top outer edge and loosest at its bottom outer \
             edge. The disc at the axis holds only a few granules, so its cells are the \
             noisiest."
            .to_owned(),
        "energy_strain.svg" => "Where the punch's work went, totals so far against the strain \
             (compression.csv's energy columns): the elastic energy stored in the \
             granules, the plastic dissipation, the contact losses (friction and the \
             kinematic contact constraints), the damping, the hourglass energy (the one-point \
             element's spurious modes; small) and the kinetic energy (small when the run is \
             quasi-static). Gravity's work and the return map's energy gap are not drawn, so the \
             terms add up to the punch's work only nearly."
            .to_owned(),
        _ => return None,
    })
}

/// The report page of a run of `scene` with `summary`, the plots `svgs`
/// (file name in `plots/`, SVG text) and the snapshots' files `sections`
/// (in strain order; the pictures shown as images, not inline: each holds
/// thousands of polygons; the tables linked).
pub fn report_html(
    scene: &Scene,
    summary: &Summary<'_>,
    svgs: &[(&str, String)],
    sections: &[SnapshotFiles],
) -> anyhow::Result<String> {
    let toml = if *scene == Scene::published() {
        DEFAULT_SCENE.to_string()
    } else {
        scene.to_toml()
    };
    let title = format!(
        "granbed bed: {} × {} granules, mesh {}",
        scene.granules, scene.granule_type, scene.mesh
    );
    let mut h = page_head(&title);
    h.push_str(&warnings_section(
        summary.error.as_deref(),
        &summary.warnings,
        "None: the run passed its checks (the quasi-static certificate, the overlaps, the \
         elements, the fits).",
    ));
    h.push_str(&key_results(summary));
    h.push_str(&fits_by_window(summary));
    h.push_str(&contact_network(summary));
    h.push_str(&stress_by_height(summary));
    h.push_str(&density_map(summary));
    writeln!(
        h,
        "<p>Files: <a href=\"compression.csv\">compression.csv</a>, {}\
         <a href=\"summary.json\">summary.json</a>, \
         <a href=\"{VTK_DIR}/{PVD_FILE}\">{VTK_DIR}/{PVD_FILE}</a> (VTU snapshots for ParaView).</p>",
        if summary.unloading.is_some() {
            "<a href=\"unloading.csv\">unloading.csv</a> (the punch withdrawn), "
        } else {
            ""
        }
    )?;
    writeln!(
        h,
        "<h2>Plots</h2>\n<p>The solid fraction D is the granules' packing fraction times \
         their own relative density (η0 at the start), so it lies well below the pour's \
         packing fraction. Each granule's mesh has its nodes on the poured sphere and flat \
         faces between them, so it holds a little less volume than the sphere, and spheres the \
         pour left touching start a few µm apart; the upper punch starts on the highest \
         granule. Over the first few per cent of strain the bed settles and rearranges under \
         the punch: the coordination number Z and the upper-punch pressure stay low, and the \
         fits' windows start well after. The Heywood coefficient α_SV starts a little above \
         the sphere's 6 (the mesh's flat faces: more surface per volume), most on coarse \
         meshes.</p>"
    )?;
    for (name, svg) in svgs {
        h.push_str(&figure(&format!("plots/{name}"), svg));
        if let Some(caption) = plot_caption(name, summary) {
            writeln!(h, "<p class=\"caption\">{}</p>", html_escape(&caption))?;
        }
    }
    if !sections.is_empty() {
        writeln!(
            h,
            "<h2>Sections through the die axis</h2>\n<p>The bed cut by the plane y = 0 at each \
             snapshot: every hex the plane cuts, coloured by its axial stress −σ<sub>zz</sub> (the \
             load runs along the bright chains from granule to granule; red: tension), the \
             granules' outlines, the die wall and the punches (the upper one moves down). The \
             granules are all of one size: a small circle is a cut off their centre. Each \
             picture has its own colour scale, up to the 99th percentile of its stresses. The \
             VTU snapshots beside them hold the whole bed; the tables beside each picture (none at \
             C = 0, before the first step) hold its contact network (contacts_&lt;k&gt;.csv: every pair of granules in contact, with its \
             forces and branch vector), its granules (granules_&lt;k&gt;.csv: centre, relative \
             density, contacts) and the network's figures (network_&lt;k&gt;.csv, the table \
             \"The contact network\" above), their columns explained at the end of this \
             page.</p>"
        )?;
        for files in sections {
            h.push_str(&picture(
                &files.section,
                "section of the bed",
                &files.tables,
            ));
        }
    }
    h.push_str(&summary_table(&rows(summary)?));
    h.push_str(&glossaries());
    writeln!(
        h,
        "<h2>Scene</h2>\n<pre>{}</pre>\n</body>\n</html>",
        html_escape(&toml)
    )?;
    Ok(h)
}

/// The files of one snapshot the report links to, as paths relative to
/// the page: its section picture and the tables beside it
/// ([`super::snapshot_tables`]) that exist.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SnapshotFiles {
    /// `vtk/section_<k>.svg`.
    pub section: String,
    /// `vtk/contacts_<k>.csv` and `vtk/granules_<k>.csv`, if there.
    pub tables: Vec<String>,
}

/// The snapshots' files in `dir`/[`VTK_DIR`] (`section_<k>.svg` and the
/// tables of the same k), in the order of k (the snapshots' strain order).
fn snapshot_files(dir: &Path) -> Vec<SnapshotFiles> {
    super::snapshots::numbered_files(&dir.join(VTK_DIR), "section_", ".svg")
        .into_iter()
        .map(|(k, _)| SnapshotFiles {
            section: format!("{VTK_DIR}/{}", super::snapshots::section_file(k)),
            tables: [
                contacts_file(k),
                granules_file(k),
                network_file(k),
                stress_file(k),
                super::density_map::map_file(k),
            ]
            .into_iter()
            .filter(|name| dir.join(VTK_DIR).join(name).is_file())
            .map(|name| format!("{VTK_DIR}/{name}"))
            .collect(),
        })
        .collect()
}

/// Writes `report.html` of a run into `dir`, linking the snapshots' files
/// there.
pub fn write_report(
    dir: &Path,
    scene: &Scene,
    summary: &Summary<'_>,
    svgs: &[(&str, String)],
) -> anyhow::Result<()> {
    let path = dir.join(REPORT_FILE);
    let html = report_html(scene, summary, svgs, &snapshot_files(dir))?;
    write_text(&path, &html)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A run of 40 output rows to C = 0.39, the pressure rising 1 kPa per
    /// row, the elements sound.
    fn loading_run() -> crate::bed::run::BedRun {
        use crate::bed::run::{BedRun, BedSample};
        let samples = (0..40)
            .map(|i| BedSample {
                strain: 0.01 * f64::from(i),
                upper_pressure_pa: 1e3 * f64::from(i),
                min_jacobian: 0.9,
                min_gauss_jacobian: 0.9,
                ..BedSample::default()
            })
            .collect();
        BedRun::of_samples(samples)
    }

    /// Every row of the summary table says what it is, whether the
    /// overlap by geometry was measured or not, with a withdrawal and its
    /// rate check and a density map (its own table, no rows), and the
    /// scene is not a row (it is shown as TOML below the table).
    #[test]
    fn every_row_has_a_meaning_and_the_scene_is_no_row() {
        use crate::assembly::overlap::Overlap;
        use crate::bed::run::{HiddenOverlap, Unloading};
        let scene = Scene::published();
        let mut run = loading_run();
        let last = *run.samples.last().unwrap();
        run.unloading = Some(Unloading {
            samples: vec![last],
            lift_off_strain: last.strain - 1e-3,
            wall_time_s: 1.0,
            cut_short: None,
        });
        run.half_speed_unloading = run
            .unloading
            .as_ref()
            .map(|u| crate::bed::unloading::UnloadingSummary::of(&run, u));
        let map = crate::bed::density_map::density_map(
            3,
            0.3,
            &crate::bed::snapshots::ElementFields::default(),
            1e-3,
            1e-3,
        );
        for measured in [false, true] {
            if measured {
                run.hidden_overlap = Some(HiddenOverlap {
                    deepest: Overlap {
                        depth_m: 1e-7,
                        granule: 3,
                        node: 17,
                        inside: 5,
                    },
                    wall_time_s: 0.1,
                });
            }
            let mut summary = crate::bed::outputs::summary(&scene, &run);
            summary.final_density_map = crate::bed::density_map::MapSummary::of(&map);
            assert!(summary.final_density_map.is_some());
            let rows = rows(&summary).unwrap();
            assert!(
                rows.iter()
                    .any(|r| r.key == "unloading.half_speed_recovery_change_rel"),
                "{rows:?}"
            );
            let blank: Vec<&str> = rows
                .iter()
                .filter(|r| r.meaning.is_empty())
                .map(|r| r.key.as_str())
                .collect();
            assert!(blank.is_empty(), "rows without a meaning: {blank:?}");
            assert!(rows.iter().all(|r| !r.key.starts_with("scene")), "{rows:?}");
            let overlap_rows = rows
                .iter()
                .filter(|r| r.key.starts_with("final_hidden_overlap"));
            assert_eq!(overlap_rows.count(), if measured { 6 } else { 1 });
        }
    }

    /// The page shows the Kawakita fit of each window, the run's own
    /// named, a window not reached as n/a, and the glossary of every
    /// column of compression.csv and of the snapshots' tables.
    #[test]
    fn the_windows_and_the_columns_are_shown() {
        use crate::bed::run::{BedRun, BedSample};
        // C = abP/(1 + bP), a = 0.4, 1/b = 50 kPa, to C = 0.22.
        let samples = (1..=22)
            .map(|i| {
                let c = 0.01 * f64::from(i);
                BedSample {
                    strain: c,
                    upper_pressure_pa: c * 50e3 / (0.4 - c),
                    min_jacobian: 0.9,
                    min_gauss_jacobian: 0.9,
                    ..BedSample::default()
                }
            })
            .collect();
        let scene = Scene::published();
        let summary = crate::bed::outputs::summary(&scene, &BedRun::of_samples(samples));
        let html = report_html(&scene, &summary, &[], &[]).unwrap();
        let table = &html[html.find("The fits by window").unwrap()..];
        let table = &table[table.find("<table>").unwrap()..table.find("</table>").unwrap()];
        for (i, (from, rows)) in [("0.1", 13), ("0.15", 8), ("0.2", 3)]
            .into_iter()
            .enumerate()
        {
            // The Heckel cell as the window's fit gives it (this run's D
            // follows no Heckel law).
            let hk = &summary.heckel_windows[i];
            assert_eq!(hk.min_strain, crate::bed::outputs::FIT_WINDOWS[i]);
            let heckel = format!(
                "<td class=\"num\" title=\"R² = {}\">{}</td>",
                num(hk.r_squared),
                kpa(hk.yield_pressure_pa)
            );
            let row = format!(
                "<tr><td>C ≥ {from}</td><td class=\"num\" title=\"R² = 1.000\">0.4000</td>\
                 <td class=\"num\" title=\"R² = 1.000\">50.00</td>{heckel}\
                 <td class=\"num\">{rows}, {rows}</td></tr>"
            );
            assert!(table.contains(&row), "no row {row} in {table}");
        }
        assert!(
            table.contains("<td>C ≥ 0.25 (the run's fits)</td><td class=\"num\" title=\"no fit")
        );
        assert!(!table.contains('✗'));
        let glossary = &html[html.find("<h2>Columns of the tables</h2>").unwrap()..];
        for (file, columns) in [
            ("compression.csv", &COMPRESSION_COLUMNS[..]),
            ("vtk/contacts_&lt;k&gt;.csv", &CONTACT_COLUMNS[..]),
            ("vtk/granules_&lt;k&gt;.csv", &GRANULE_COLUMNS[..]),
            ("vtk/network_&lt;k&gt;.csv", &NETWORK_COLUMNS[..]),
            ("vtk/stress_&lt;k&gt;.csv", &STRESS_COLUMNS[..]),
            ("vtk/density_map_&lt;k&gt;.csv", &MAP_COLUMNS[..]),
        ] {
            let table = &glossary[glossary.find(&format!("<h3>{file}</h3>")).unwrap()..];
            let table = &table[..table.find("</table>").unwrap()];
            for (name, _) in columns {
                let cell = format!("<td class=\"value\">{name}</td>");
                assert!(table.contains(&cell), "{file}: {name}");
            }
        }
    }

    /// A run without warnings says so rather than showing nothing.
    #[test]
    fn no_warnings_is_said() {
        let scene = Scene::published();
        let run = loading_run();
        let mut summary = crate::bed::outputs::summary(&scene, &run);
        let some = report_html(&scene, &summary, &[], &[]).unwrap();
        assert!(!summary.warnings.is_empty() && !some.contains("None: the run passed"));
        summary.warnings.clear();
        let none = report_html(&scene, &summary, &[], &[]).unwrap();
        assert!(none.contains("<h2>Warnings</h2>\n<p>None: the run passed its checks"));
    }
}
