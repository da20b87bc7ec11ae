//! The search settings as a front end's options give them: every option optional (the
//! default where absent), checked against the ranges of [`crate::limits`] and the rule that
//! a budget holds at least the first generation.

use kinergy_io::InvalidSetting;
use kinergy_solver::FitObjective;

use super::FitSettings;
use crate::anneal::AnnealSettings;
use crate::limits;

/// What the fit minimizes, by name: `positions` or `positions+speed`.
pub const OBJECTIVES: [&str; 2] = ["positions", "positions+speed"];

/// A fit's search options, as `kinergy fit`/`compare` flags or Python's keywords give them.
#[derive(Debug, Clone, Default)]
pub struct SearchOptions {
    /// Seed of every random draw.
    pub seed: u64,
    /// Evaluations per model fit.
    pub budget: Option<usize>,
    /// Members of the annealing population.
    pub population: Option<usize>,
    /// Initial temperature relative to the initial mean score.
    pub temperature: Option<f64>,
    /// The stopping rule's relative change.
    pub stable_change: Option<f64>,
    /// The stopping rule's window, iterations.
    pub stable_window: Option<usize>,
    /// [`OBJECTIVES`]: `positions` (default) or `positions+speed`.
    pub objective: Option<String>,
    /// Seconds of the speed term (`positions+speed`).
    pub speed_weight: Option<f64>,
    /// A library's coarser stopping rule where none is given
    /// ([`AnnealSettings::for_library`]).
    pub library: bool,
}

impl SearchOptions {
    /// The settings, checked: each option within its range, the budget at least one
    /// generation, the objective one of [`OBJECTIVES`].
    pub fn settings(&self) -> Result<FitSettings, InvalidSetting> {
        let defaults = if self.library {
            AnnealSettings::default().for_library()
        } else {
            AnnealSettings::default()
        };
        let anneal = AnnealSettings {
            seed: self.seed,
            max_evaluations: self.budget.unwrap_or(defaults.max_evaluations),
            population: self.population.unwrap_or(defaults.population),
            temperature: self.temperature.unwrap_or(defaults.temperature),
            stable_tolerance: self.stable_change.unwrap_or(defaults.stable_tolerance),
            stable_window: self.stable_window.unwrap_or(defaults.stable_window),
            ..defaults
        };
        InvalidSetting::in_range("budget", anneal.max_evaluations, limits::BUDGET)?;
        InvalidSetting::in_range("population", anneal.population, limits::POPULATION)?;
        InvalidSetting::in_range("temperature", anneal.temperature, limits::TEMPERATURE)?;
        let change = anneal.stable_tolerance;
        InvalidSetting::in_range("stable_change", change, limits::STABLE_CHANGE)?;
        InvalidSetting::in_range("stable_window", anneal.stable_window, limits::STABLE_WINDOW)?;
        InvalidSetting::require(
            anneal.max_evaluations >= anneal.population,
            "budget",
            format!(
                "{}: at least population ({}), the evaluations of the first generation",
                anneal.max_evaluations, anneal.population
            ),
        )?;
        let weight = self
            .speed_weight
            .unwrap_or(FitObjective::DEFAULT_SPEED_WEIGHT);
        InvalidSetting::in_range("speed_weight", weight, limits::SPEED_WEIGHT)?;
        let objective = match self.objective.as_deref().unwrap_or(OBJECTIVES[0]) {
            "positions" if self.speed_weight.is_some() => {
                let why = "weighs the speed term of the objective positions+speed: choose it, \
                           or give no speed weight";
                return Err(InvalidSetting::new("speed_weight", why));
            }
            "positions" => FitObjective::Positions,
            "positions+speed" => FitObjective::PositionsSpeed {
                speed_weight_s: weight,
            },
            other => {
                let why = format!("`{other}`: expected positions or positions+speed");
                return Err(InvalidSetting::new("objective", why));
            }
        };
        Ok(FitSettings {
            anneal,
            objective,
            ..FitSettings::default()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn absent_options_are_the_defaults_and_a_library_stops_coarser() {
        let one = SearchOptions::default().settings().unwrap();
        assert_eq!(
            one.anneal,
            AnnealSettings {
                seed: 0,
                ..AnnealSettings::default()
            }
        );
        let library = SearchOptions {
            library: true,
            ..SearchOptions::default()
        };
        let library = library.settings().unwrap().anneal;
        assert_eq!(
            library,
            AnnealSettings {
                seed: 0,
                ..AnnealSettings::default().for_library()
            }
        );
    }

    #[test]
    fn a_budget_below_one_generation_and_unknown_objectives_are_refused_by_name() {
        let small = SearchOptions {
            budget: Some(5),
            population: Some(8),
            ..SearchOptions::default()
        };
        let e = small.settings().unwrap_err();
        assert_eq!(
            (e.field.as_str(), e.why.contains("at least population (8)")),
            ("budget", true)
        );
        let odd = SearchOptions {
            objective: Some("speed".into()),
            ..SearchOptions::default()
        };
        assert_eq!(odd.settings().unwrap_err().field, "objective");
        let ignored = SearchOptions {
            speed_weight: Some(0.1),
            ..SearchOptions::default()
        };
        assert_eq!(ignored.settings().unwrap_err().field, "speed_weight");
        let nan = SearchOptions {
            temperature: Some(f64::NAN),
            ..SearchOptions::default()
        };
        assert_eq!(nan.settings().unwrap_err().field, "temperature");
    }
}
