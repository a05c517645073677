//! A noise statistic is one row of `config::STATISTICS`: every row appears in the default
//! configuration file, falls back from `[filter]` to the truth, is validated with its range on
//! both sides, is a statistic of the sensitivity study, a likelihood key when it is of a
//! searchable kind, and a row of the report's parameter table and of its filter differences.
//!
//! The proof that a row is all it takes is the throwaway statistic, a row that exists only
//! with `cargo test --release --features throwaway-statistic --test statistic_registry`: the
//! test named `the_throwaway_row_reaches_everything` finds it everywhere (and fails without the
//! row).

use accelcal::config::statistics::{Kind, ParamRow};
use accelcal::config::{Config, DEFAULT_TOML, STATISTICS, Statistic, show};
use accelcal::error::ConfigError;
use accelcal::likelihood::Key;
use accelcal::model::Model;
use accelcal::report::params::{filter_differences, params};
use accelcal::sensitivity::AssumedStatistic;
use accelcal::study::{Silent, Study};

/// The lines of `[section]` in the default file.
fn section_lines(section: &str) -> Vec<&'static str> {
    let header = format!("[{section}]");
    DEFAULT_TOML
        .lines()
        .skip_while(|l| *l != header)
        .skip(1)
        .take_while(|l| !l.starts_with('['))
        .collect()
}

/// The configuration text that selects the bias model `s` belongs to, on both sides.
fn bias_text(s: &Statistic) -> String {
    match s.bias_model {
        Some(kind) => format!("[accelerometer]\nbias_model = \"{kind}\"\n"),
        None => String::new(),
    }
}

/// `s`'s truth set to `value` in its section (with its bias model), plus `more`.
fn with_truth(s: &Statistic, value: f64, more: &str) -> Config {
    let mut text = bias_text(s);
    if s.truth_section() != "accelerometer" || text.is_empty() {
        text.push_str(&format!("[{}]\n", s.truth_section()));
    }
    text.push_str(&format!("{} = {}\n{more}", s.truth_key(), show(value)));
    Config::from_toml_str(&text).unwrap_or_else(|e| panic!("{text}: {e}"))
}

/// The field and message of the error `Model::new` gives for `c`.
fn refusal(c: &Config) -> (&'static str, String) {
    match Model::new(c) {
        Err(e @ ConfigError::Invalid { field, .. }) => (field, e.to_string()),
        Err(e) => panic!("unexpected {e}"),
        Ok(_) => panic!("accepted {c:?}"),
    }
}

/// How the validation writes `s`'s range on one side.
fn range_words(r: accelcal::config::statistics::Range) -> String {
    let open = if r.lo_open { "(" } else { "[" };
    format!("in {open}{}, {}]", show(r.lo), show(r.hi))
}

/// Everything one row should reach, but the report (see [`in_the_report`]).
fn appears_everywhere(s: &'static Statistic) {
    let key = s.key();
    // The default file: the truth's key in its section (commented out for a bias model's
    // optional parameter), the filter's key commented out in [filter], both at the default.
    let truth_line = format!("{} = {}", s.truth_key(), s.default_toml);
    let truth_line = match s.bias_model {
        Some(_) => format!("# {truth_line}"),
        None => truth_line,
    };
    assert!(
        section_lines(s.truth_section()).contains(&truth_line.as_str()),
        "{truth_line} not in [{}] of\n{DEFAULT_TOML}",
        s.truth_section()
    );
    let filter_line = format!("# {key} = {}", s.default_toml);
    assert!(
        section_lines("filter").contains(&filter_line.as_str()),
        "{filter_line}"
    );
    assert_eq!(s.default_toml.parse::<f64>().unwrap(), s.default, "{key}");
    let default = Config::from_toml_str(DEFAULT_TOML).unwrap();
    if s.bias_model.is_none() {
        assert_eq!(default.truth_value(s), Some(s.default), "{key}");
    }

    // The fallback: a [filter] key left out takes the truth's value.
    let v = s.default * 3.0;
    let c = with_truth(s, v, "");
    assert_eq!(c.filter_value(s), Some(v), "{key}");
    assert!(c.filter_matches_truth(), "{key}");
    let filter = format!("[filter]\n{key} = {}\n", show(2.0 * v));
    let c = with_truth(s, v, &filter);
    assert_eq!(c.filter_value(s), Some(2.0 * v), "{key}");
    assert!(!c.filter_matches_truth(), "{key}");
    Model::new(&c).unwrap_or_else(|e| panic!("{key}: {e}"));

    // The validation: each side's key, out of its range, is named with the range.
    let bad = 2.0 * s.truth_range.hi;
    let (field, message) = refusal(&with_truth(s, bad, ""));
    assert_eq!(field, s.truth_path);
    assert!(message.contains(&range_words(s.truth_range)), "{message}");
    let filter = format!("[filter]\n{key} = {}\n", show(2.0 * s.filter_range.hi));
    let (field, message) = refusal(&with_truth(s, v, &filter));
    assert_eq!(field, s.filter_path);
    assert!(message.contains(&range_words(s.filter_range)), "{message}");

    // The sensitivity study: a statistic the filter assumes, scaled by its kind.
    let c = with_truth(s, v, "");
    let assumed = AssumedStatistic(s);
    assert!(AssumedStatistic::of(&c).contains(&assumed), "{key}");
    assert_eq!(AssumedStatistic::from_name(key), Some(assumed));
    let scaled = assumed.scaled(&c, 2.0);
    let times = if s.kind == Kind::Variance { 4.0 } else { 2.0 };
    assert_eq!(scaled.filter_value(s), Some(v * times), "{key}");

    // The likelihood: a key exactly when the row is of a searchable kind.
    assert_eq!(Key::parse(key).is_some(), s.searchable(), "{key}");
    if let Some(k) = Key::parse(key) {
        assert_eq!((k.unit(), k.symbol()), (s.unit, s.symbol));
    }
}

/// The report: a row of the parameter table (when the row has one of its own) and a sentence
/// of the filter's differences from the truth, for every row `rows` of a small study whose
/// filter assumes twice every truth.
fn in_the_report(rows: &[&'static Statistic]) {
    let mut text = String::from("[profile]\nduration_s = 2.0\n[ensemble]\nrealizations = 50\n");
    text.push_str("[filter]\n");
    for s in rows.iter().filter(|s| s.bias_model.is_none()) {
        text.push_str(&format!("{} = {}\n", s.key(), show(2.0 * s.default)));
    }
    let config = Config::from_toml_str(&text).unwrap();
    let study = Study::run(&Model::new(&config).unwrap(), &mut Silent).unwrap();
    let table = params(&study);
    let differences = filter_differences(&study);
    for s in rows {
        let found = table.iter().find(|r| r.field == s.truth_path);
        match s.param_row {
            ParamRow::Own(_) => {
                let r = found.unwrap_or_else(|| panic!("no row {}", s.truth_path));
                assert_eq!(r.unit, s.unit);
            }
            ParamRow::WithMean | ParamRow::Hidden => assert!(found.is_none()),
        }
        if s.bias_model.is_none() {
            assert!(
                differences.iter().any(|d| d.starts_with(s.words)),
                "{}: {differences:?}",
                s.key()
            );
        }
    }
}

#[test]
fn every_row_appears_everywhere() {
    assert!(STATISTICS.len() >= 8);
    for s in STATISTICS {
        appears_everywhere(s);
    }
}

#[test]
fn every_row_is_in_the_report() {
    in_the_report(&STATISTICS.iter().collect::<Vec<_>>());
}

#[test]
fn the_historical_names_are_rows() {
    for (key, s) in [
        ("accel_noise_var_m2_s4", &Statistic::ACCEL_NOISE_VAR),
        ("bias_var_m2_s4", &Statistic::BIAS_VAR),
        ("gps_position_sigma_m", &Statistic::GPS_POSITION_SIGMA),
        ("gps_velocity_sigma_m_s", &Statistic::GPS_VELOCITY_SIGMA),
        (
            "initial_position_sigma_m",
            &Statistic::INITIAL_POSITION_SIGMA,
        ),
        (
            "initial_velocity_sigma_m_s",
            &Statistic::INITIAL_VELOCITY_SIGMA,
        ),
        (
            "bias_random_walk_m_s2_per_sqrt_s",
            &Statistic::BIAS_RANDOM_WALK,
        ),
        ("bias_correlation_time_s", &Statistic::BIAS_CORRELATION_TIME),
    ] {
        assert_eq!(Statistic::from_key(key), Some(s));
    }
    // summary.json's order of the keys there were before the table (a new key may come
    // between them, with the noise it belongs to).
    let historical = [
        "gps_position_sigma_m",
        "gps_velocity_sigma_m_s",
        "accel_noise_var_m2_s4",
        "bias_random_walk_m_s2_per_sqrt_s",
    ];
    let names: Vec<&str> = Key::ALL
        .iter()
        .map(|k| k.name())
        .filter(|n| historical.contains(n))
        .collect();
    assert_eq!(
        names,
        [
            "gps_position_sigma_m",
            "gps_velocity_sigma_m_s",
            "accel_noise_var_m2_s4",
            "bias_random_walk_m_s2_per_sqrt_s"
        ]
    );
}

/// The throwaway row, found by its key as any statistic is.
#[cfg(feature = "throwaway-statistic")]
#[test]
fn the_throwaway_row_reaches_everything() {
    let name = "throwaway_sigma_m";
    assert!(section_lines("gps").contains(&"throwaway_sigma_m = 0.5"));
    assert!(section_lines("filter").contains(&"# throwaway_sigma_m = 0.5"));
    assert!(AssumedStatistic::ALL.iter().any(|s| s.name() == name));
    assert!(Key::ALL.iter().any(|k| k.name() == name));
    let s = Statistic::from_key(name).expect("the throwaway row is in STATISTICS");
    appears_everywhere(s);
    in_the_report(&[s]);
}
