//! Browser front end of granbed: the kernel's single-granule platen
//! experiment ([`granbed_kernel::scene::platens`], the same code as
//! `granbed-cli granule`) behind a `wasm_bindgen` handle.
//!
//! JavaScript constructs a [`Granule`] from an object of inputs, calls
//! [`Granule::step`] in chunks (from a Web Worker or between animation
//! frames) and reads the curve, the surface and, at the end, σ_est,
//! σ_y,eff0 and the CSV. Every failure comes back as a JavaScript `Error`
//! whose message names the field and its allowed range, with the fields
//! `field`, `value` and `allowed` set (several inputs out of range: every
//! one named, a line each, and listed in `fields`); nothing here panics on
//! bad input.
//!
//! The logic lives in [`experiment`] (plain Rust, tested natively); this
//! file only converts between it and JavaScript values.

extern crate alloc;

pub mod experiment;
pub mod mesh;

pub use granbed_kernel as kernel;

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

use granbed_kernel::material::GranuleType;
use wasm_bindgen::prelude::*;

use experiment::{Error, Experiment, Inputs, MATERIAL_FIELDS};

/// Inputs other than [`MATERIAL_FIELDS`] that [`Granule::new`] accepts.
const OTHER_FIELDS: [&str; 4] = ["type", "diameter_m", "diameter_mm", "mesh"];

fn js_error(e: &Error) -> JsValue {
    let err = js_sys::Error::new(&e.message);
    let set = |key: &str, value: JsValue| {
        let _ = js_sys::Reflect::set(&err, &JsValue::from_str(key), &value);
    };
    if let Some(field) = e.field {
        set("field", JsValue::from_str(field));
    }
    if let Some(value) = e.value {
        set("value", JsValue::from_f64(value));
    }
    if let Some(allowed) = e.allowed {
        set("allowed", JsValue::from_str(allowed));
    }
    if !e.fields.is_empty() {
        let fields: js_sys::Array = e.fields.iter().map(|f| JsValue::from_str(f)).collect();
        set("fields", fields.into());
    }
    err.into()
}

fn message(text: String) -> JsValue {
    js_error(&Error::other(text))
}

fn granule_type(name: &str) -> Result<GranuleType, JsValue> {
    name.trim().parse().map_err(|_| {
        let mut e = Error::other(format!(
            "granule type `{name}` is unknown: the types are A1, A2, A3, B1, B2, B3, C1, C2, C3 \
             (field `type`)"
        ));
        e.field = Some("type");
        e.fields = alloc::vec!["type"];
        e.allowed = Some("A1 … C3");
        js_error(&e)
    })
}

/// Parses "NxM" (e.g. "8x2").
fn mesh_level(text: &str) -> Option<(u32, u32)> {
    let (n, m) = text.split_once(['x', 'X'])?;
    Some((n.trim().parse().ok()?, m.trim().parse().ok()?))
}

/// Reads the inputs object (see [`Granule::new`]), with every input out of
/// range: [`experiment::refusals`] and a diameter in mm that is (checked
/// while reading, to be named in mm).
fn inputs_from_js(obj: &JsValue) -> Result<(Inputs, Vec<Error>), JsValue> {
    if !obj.is_object() {
        return Err(message(
            "the inputs must be an object such as { type: \"B2\", poisson_ratio: 0.3 }".into(),
        ));
    }
    let get = |key: &str| {
        js_sys::Reflect::get(obj, &JsValue::from_str(key))
            .ok()
            .filter(|v| !v.is_undefined() && !v.is_null())
    };
    let type_name = match get("type") {
        Some(v) => v
            .as_string()
            .ok_or_else(|| message("`type` must be a string such as \"B2\"".into()))?,
        None => "B2".into(),
    };
    let mut inputs = Inputs::standard(granule_type(&type_name)?);
    let keys = js_sys::Object::keys(&js_sys::Object::from(obj.clone()));
    for key in keys.iter() {
        let key = key.as_string().unwrap_or_default();
        if !MATERIAL_FIELDS.contains(&key.as_str()) && !OTHER_FIELDS.contains(&key.as_str()) {
            return Err(message(format!(
                "unknown input `{key}`: the inputs are type, mesh, diameter_m or diameter_mm, {}",
                MATERIAL_FIELDS.join(", ")
            )));
        }
    }
    let number = |key: &str| -> Result<Option<f64>, JsValue> {
        match get(key) {
            None => Ok(None),
            Some(v) => v.as_f64().map(Some).ok_or_else(|| {
                message(format!(
                    "{} must be a number (field `{key}`)",
                    experiment::field_label(key)
                ))
            }),
        }
    };
    for field in MATERIAL_FIELDS {
        if let Some(v) = number(field)? {
            inputs.set(field, v);
        }
    }
    let mut diameter_refused = None;
    match (number("diameter_m")?, number("diameter_mm")?) {
        (Some(_), Some(_)) => {
            return Err(message(
                "give the granule diameter once: diameter_m or diameter_mm, not both".into(),
            ));
        }
        (Some(d), None) => inputs.diameter_m = d,
        (None, Some(d_mm)) => match experiment::diameter_m_of_mm(d_mm) {
            Ok(d) => inputs.diameter_m = d,
            // Named with every other input out of range, in mm.
            Err(e) => diameter_refused = Some(e),
        },
        (None, None) => {}
    }
    if let Some(v) = get("mesh") {
        let text = v.as_string().unwrap_or_default();
        inputs.mesh = mesh_level(&text).ok_or_else(|| {
            message(format!(
                "mesh level `{text}` is not NxM such as \"8x2\" (field `mesh`)"
            ))
        })?;
    }
    let mut refused = experiment::refusals(&inputs);
    refused.extend(diameter_refused);
    Ok((inputs, refused))
}

/// The preset material parameters of granule type `name` (A1 … C3) as an
/// object `{ yield_stress_pa, eta0, youngs_modulus_pa, poisson_ratio, cp,
/// eta_c, friction, true_density_kg_m3, diameter_m }`.
#[wasm_bindgen]
pub fn preset(name: &str) -> Result<JsValue, JsValue> {
    let p = granule_type(name)?.params();
    let values = [
        p.yield_stress_pa,
        p.eta0,
        p.youngs_modulus_pa,
        p.poisson_ratio,
        p.cp,
        p.eta_c,
        p.friction,
        p.true_density_kg_m3,
    ];
    let obj = js_sys::Object::new();
    let pairs = MATERIAL_FIELDS
        .iter()
        .zip(values)
        .chain([(&"diameter_m", experiment::STANDARD_DIAMETER_M)]);
    for (key, value) in pairs {
        js_sys::Reflect::set(&obj, &JsValue::from_str(key), &JsValue::from_f64(value))?;
    }
    Ok(obj.into())
}

/// The CSV's columns, `[[name, meaning], …]` in the file's order: the
/// kernel's `SAMPLE_COLUMNS`, which the CLI's `force_displacement.csv`
/// and its report's glossary use too.
#[wasm_bindgen]
pub fn csv_columns() -> js_sys::Array {
    granbed_kernel::scene::platens::SAMPLE_COLUMNS
        .iter()
        .map(|(name, meaning)| {
            js_sys::Array::of2(&JsValue::from_str(name), &JsValue::from_str(meaning))
        })
        .collect()
}

/// Checks `inputs` as [`Granule::new`] reads and checks them, without
/// setting up a run: every input out of range as `[{ message, field }, …]`
/// in the order `new` names them (empty: all in range); throws only where
/// `new` throws before any range is judged (an unknown key, a value not a
/// number, a bad type or mesh). A field given as NaN is refused and judged
/// as [`MaterialParams::refusals`] judges a refused one, so a page can
/// check the fields it could read while naming those it could not (passed
/// as NaN) itself.
///
/// [`MaterialParams::refusals`]: granbed_kernel::material::MaterialParams::refusals
#[wasm_bindgen]
pub fn check(inputs: &JsValue) -> Result<js_sys::Array, JsValue> {
    let (_, refused) = inputs_from_js(inputs)?;
    refused
        .iter()
        .map(|e| {
            let entry = js_sys::Object::new();
            js_sys::Reflect::set(&entry, &"message".into(), &JsValue::from_str(&e.message))?;
            let field = e.field.map_or(JsValue::NULL, JsValue::from_str);
            js_sys::Reflect::set(&entry, &"field".into(), &field)?;
            Ok::<JsValue, JsValue>(entry.into())
        })
        .collect()
}

/// The version of granbed this module was built from.
#[wasm_bindgen]
pub fn version() -> String {
    env!("CARGO_PKG_VERSION").into()
}

/// One granule compressed between two platens (octant symmetry, 5 mm/s,
/// to 40 % strain: the standard experiment of `granbed-cli granule`).
#[wasm_bindgen]
pub struct Granule {
    run: Experiment,
}

#[wasm_bindgen]
impl Granule {
    /// Sets up the experiment from `{ type: "B2", mesh: "8x2", diameter_m,
    /// yield_stress_pa, eta0, youngs_modulus_pa, poisson_ratio, cp, eta_c,
    /// friction, true_density_kg_m3 }`: the preset of `type` (default B2)
    /// with every given field overriding it. The diameter may be given in
    /// mm instead (`diameter_mm`, its errors in mm), not both. Throws an
    /// `Error` naming the field and its allowed range (`field`, `value`,
    /// `allowed` set), or every field out of range at once, a line each
    /// (`fields` lists them all, `field` and the rest are the first's).
    #[wasm_bindgen(constructor)]
    pub fn new(inputs: &JsValue) -> Result<Granule, JsValue> {
        let (inputs, refused) = inputs_from_js(inputs)?;
        if let Some(e) = Error::all(refused) {
            return Err(js_error(&e));
        }
        let run = Experiment::new(inputs).map_err(|e| js_error(&e))?;
        Ok(Self { run })
    }

    /// Advances up to `max_steps` time steps; returns the progress 0…1.
    /// Throws if the kernel stops the run (the samples so far remain).
    pub fn step(&mut self, max_steps: u32) -> Result<f64, JsValue> {
        self.run.step(max_steps).map_err(|e| js_error(&e))?;
        Ok(self.run.progress())
    }

    /// True once the final strain is reached or the run failed.
    pub fn finished(&self) -> bool {
        self.run.finished()
    }

    /// Fraction of the final strain reached, 0…1.
    pub fn progress(&self) -> f64 {
        self.run.progress()
    }

    /// Current strain x/d.
    pub fn strain(&self) -> f64 {
        self.run.strain()
    }

    /// Time steps taken.
    pub fn steps(&self) -> f64 {
        self.run.steps() as f64
    }

    /// Final strain of the run.
    pub fn final_strain(&self) -> f64 {
        self.run.params().final_strain
    }

    /// Granule diameter d, m.
    pub fn diameter_m(&self) -> f64 {
        self.run.diameter()
    }

    /// Samples so far.
    pub fn sample_count(&self) -> usize {
        self.run.samples().len()
    }

    /// Platen approach x of every sample, m.
    pub fn displacements_m(&self) -> Vec<f64> {
        self.run.samples().iter().map(|s| s.approach_m).collect()
    }

    /// x/d of every sample.
    pub fn strains(&self) -> Vec<f64> {
        self.run.samples().iter().map(|s| s.strain).collect()
    }

    /// Platen force of every sample (mean of both platens, averaged over
    /// the sample interval), N.
    pub fn forces_n(&self) -> Vec<f64> {
        self.run
            .samples()
            .iter()
            .map(granbed_kernel::scene::platens::PlatenSample::mean_force)
            .collect()
    }

    /// Current node positions of the simulated octant, `[x0, y0, z0, x1, …]`, m.
    pub fn positions(&self) -> Vec<f64> {
        self.run.positions().iter().flatten().copied().collect()
    }

    /// Outer surface quads of the octant, four node indices each
    /// (counter-clockwise seen from outside).
    pub fn surface_quads(&self) -> Vec<u32> {
        self.run.mesh().quads.iter().flatten().copied().collect()
    }

    /// σ_est = 4/(πd)·dF/dx fitted over 10–40 % strain, Pa; `undefined`
    /// with fewer than two samples there.
    pub fn sigma_est_pa(&self) -> Option<f64> {
        self.run.measures().sigma_est_pa
    }

    /// σ_y,eff0 = √a2(η0)·σy, Pa.
    pub fn sigma_eff0_pa(&self) -> f64 {
        self.run.measures().sigma_eff0_pa
    }

    /// The fitted slope dF/dx, N/m; `undefined` without a fit.
    pub fn slope_n_per_m(&self) -> Option<f64> {
        self.run.measures().fit.map(|f| f.slope)
    }

    /// The fitted intercept, N; `undefined` without a fit.
    pub fn intercept_n(&self) -> Option<f64> {
        self.run.measures().fit.map(|f| f.intercept)
    }

    /// R² of the fit; `undefined` without a fit.
    pub fn fit_r_squared(&self) -> Option<f64> {
        self.run.measures().fit.map(|f| f.r_squared)
    }

    /// Largest kinetic / internal work ratio over the second half of the
    /// run (the quasi-static certificate's figure); `undefined` before any
    /// internal work.
    pub fn max_kinetic_to_internal(&self) -> Option<f64> {
        self.run.measures().quasi_static.max_kinetic_to_internal
    }

    /// Whether the run so far passes the quasi-static certificate (kinetic
    /// energy below 1 % of the internal work over its second half).
    pub fn quasi_static(&self) -> bool {
        self.run.measures().quasi_static.passed
    }

    /// The certificate's limit on the kinetic / internal work ratio.
    pub fn kinetic_to_internal_limit(&self) -> f64 {
        granbed_kernel::analysis::quasi_static::KINETIC_TO_INTERNAL_LIMIT
    }

    /// Mass scaling F of the experiment (masses ×F).
    pub fn mass_scaling(&self) -> f64 {
        self.run.params().mass_scaling
    }

    /// The error message that stopped the run, if any.
    pub fn error(&self) -> Option<String> {
        self.run.error().map(|e| e.message.clone())
    }

    /// The curve as CSV: the columns and format of `granbed-cli granule`'s
    /// `force_displacement.csv`.
    pub fn csv(&self) -> String {
        self.run.csv()
    }
}
