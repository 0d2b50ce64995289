//! Runs too long to finish, refused before they start: the steps a run's
//! stable time step and its simulated duration imply, against a cap far
//! above any useful run. Inputs that are each in range can still combine
//! into one (a stiff, light material: E = 10¹³ Pa with a true density of
//! 10⁻³ kg/m³ gives a wave speed 4·10⁶ times the standard granule's), and
//! such a run would go on for years with nothing to show.

/// The estimate of a run's steps and what it is made of.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RunLength {
    /// Simulated time the run covers, s.
    pub duration_s: f64,
    /// Its stable time step at the start, s.
    pub time_step_s: f64,
    /// The material's dilatational wave speed √((λ + 2μ)/ρ0), m/s.
    pub wave_speed_m_s: f64,
}

impl RunLength {
    /// Steps: the duration over the step (the step shrinks as elements
    /// flatten, so a run takes more).
    pub fn steps(&self) -> f64 {
        self.duration_s / self.time_step_s
    }

    /// Why the run cannot go on, if it would take more than `cap` steps
    /// (or the estimate is not a number): the message names `fields`, the
    /// inputs that set the step and the duration.
    pub fn refusal(&self, cap: f64, fields: &str) -> Option<String> {
        let steps = self.steps();
        (steps.is_nan() || steps > cap).then(|| {
            format!(
                "the run would take about {} steps (a stable time step of {} s, the material's \
                 wave speed being {} m/s, over {} s of simulated time), more than the {} \
                 allowed: {fields} set them",
                crate::numbers::significant(steps, 2),
                crate::numbers::significant(self.time_step_s, 3),
                crate::numbers::significant(self.wave_speed_m_s, 3),
                crate::numbers::significant(self.duration_s, 3),
                crate::numbers::significant(cap, 2),
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_run_past_the_cap_or_not_a_number_is_refused_by_its_fields() {
        let run = RunLength {
            duration_s: 1.0,
            time_step_s: 1e-6,
            wave_speed_m_s: 30.0,
        };
        assert_eq!(run.steps(), 1e6);
        assert_eq!(run.refusal(1e6, "`--a`"), None);
        let e = run.refusal(1e5, "`--a` and `--b`").unwrap();
        assert!(
            e.contains("about 1.0e6 steps") && e.contains("`--a` and `--b` set them"),
            "{e}"
        );
        let nan = RunLength {
            time_step_s: f64::NAN,
            ..run
        };
        assert!(nan.refusal(1e9, "x").is_some());
    }
}
