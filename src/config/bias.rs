//! The bias model of the truth and of the filter: the filter's keys fall back to the truth's.

use super::{BiasModelKind, Config};

impl Config {
    /// The filter's assumed bias model kind: `filter.bias_model`, or the truth's.
    pub fn filter_bias_model_kind(&self) -> BiasModelKind {
        self.filter
            .bias_model
            .unwrap_or(self.accelerometer.bias_model)
    }

    /// True when the filter assumes the truth's bias model and its parameter.
    pub(super) fn filter_bias_matches_truth(&self) -> bool {
        let a = &self.accelerometer;
        match self.filter_bias_model_kind() {
            kind if kind != a.bias_model => false,
            BiasModelKind::Constant => true,
            BiasModelKind::RandomWalk => {
                self.filter_bias_random_walk_m_s2_per_sqrt_s() == a.bias_random_walk_m_s2_per_sqrt_s
            }
            BiasModelKind::GaussMarkov => {
                self.filter_bias_correlation_time_s() == a.bias_correlation_time_s
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bias_model_is_written_only_when_it_drifts() {
        let c = Config::default();
        assert!(!c.to_toml_string().contains("bias_model"));
        let text = "[accelerometer]\nbias_model = \"random_walk\"\n\
                    bias_random_walk_m_s2_per_sqrt_s = 0.02\n";
        let c = Config::from_toml_str(text).unwrap();
        assert_eq!(c.accelerometer.bias_model, BiasModelKind::RandomWalk);
        assert_eq!(c.filter_bias_model_kind(), BiasModelKind::RandomWalk);
        assert_eq!(c.filter_bias_random_walk_m_s2_per_sqrt_s(), Some(0.02));
        assert!(c.filter_matches_truth());
        assert_eq!(Config::from_toml_str(&c.to_toml_string()).unwrap(), c);
        let mut wrong = c.clone();
        wrong.filter.bias_model = Some(BiasModelKind::Constant);
        assert!(!wrong.filter_matches_truth());
        let mut wrong = c;
        wrong.filter.bias_random_walk_m_s2_per_sqrt_s = Some(0.01);
        assert!(!wrong.filter_matches_truth());
    }
}
