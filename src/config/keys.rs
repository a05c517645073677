//! Which keys a configuration file sets, as opposed to the defaults it leaves them at: a
//! recording's calibration takes some values from the log when the file is silent.

use super::ConfigText;
use super::source::span_of;

impl ConfigText {
    /// Whether the file sets the table or key at dotted `path` (`"initial"`,
    /// `"accelerometer.sample_rate_hz"`).
    pub fn sets(&self, path: &str) -> bool {
        span_of(&self.text, path).is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_key_or_table_is_set_only_when_the_file_writes_it() {
        let text = "[accelerometer]\nsample_rate_hz = 104.35668282688978\n";
        let t = ConfigText {
            file: "c.toml".into(),
            text: text.into(),
        };
        assert!(t.sets("accelerometer.sample_rate_hz"));
        assert!(t.sets("accelerometer"));
        assert!(!t.sets("initial"));
        assert!(!t.sets("accelerometer.noise_var_m2_s4"));
        let t = ConfigText {
            file: "c.toml".into(),
            text: "initial.velocity_mean_m_s = 8.0\n".into(),
        };
        assert!(t.sets("initial"));
    }
}
