//! The configuration a Python call names: none (the defaults), a file, or TOML text (a dict is
//! turned into TOML text by the Python layer).

use pyo3::prelude::*;

use accelcal::config::{Config, ConfigText};
use accelcal::error::ConfigError;

/// Where a call's configuration comes from.
pub(crate) enum Source {
    /// A file's path.
    File(String),
    /// TOML text, with the name its errors give it.
    Text { name: String, text: String },
}

impl Source {
    /// `kind` is "file", "dict" or "text"; `value` the path or the TOML text.
    pub(crate) fn of(kind: &str, value: String) -> Source {
        match kind {
            "file" => Source::File(value),
            "dict" => Source::Text {
                name: "<dict>".to_string(),
                text: value,
            },
            _ => Source::Text {
                name: "<config>".to_string(),
                text: value,
            },
        }
    }

    /// The text, read from the file when the source is one.
    pub(crate) fn read(self) -> Result<ConfigText, ConfigError> {
        match self {
            Source::File(path) => ConfigText::read(std::path::Path::new(&path)),
            Source::Text { name, text } => Ok(ConfigText { file: name, text }),
        }
    }
}

/// The configuration text of `source`, if any, and the configuration it holds (the defaults
/// without one), as the command line loads it.
pub(crate) fn load(source: Option<Source>) -> Result<(Option<ConfigText>, Config), ConfigError> {
    let text = source.map(Source::read).transpose()?;
    let config = match &text {
        Some(t) => t.parse()?,
        None => Config::default(),
    };
    Ok((text, config))
}

/// The default configuration file, as `accelcal config` prints it.
#[pyfunction]
pub(crate) fn default_config() -> &'static str {
    accelcal::config::DEFAULT_TOML
}

/// The TOML text of a configuration given as a dict (passed here as JSON text): the same keys,
/// so that the library reads it as it reads a file.
#[pyfunction]
pub(crate) fn toml_of_json(json: &str) -> PyResult<String> {
    let table: toml::Table = serde_json::from_str(json).map_err(|e| {
        crate::bad_input(format!(
            "config: the dict is not a configuration (tables of numbers, strings, booleans and \
             lists): {e}"
        ))
    })?;
    toml::to_string(&table).map_err(crate::bad_input)
}
