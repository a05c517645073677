//! A static three-axis IMU log as CSV (`allan --imu`): `t_s` and any of the six channel
//! columns, each column read and checked exactly as the one-column form reads its column
//! ([`read_static_log`]: every row by the log reader, the steps against the median), from the
//! text read once; or its channels read as [`Record`]s, the file read again as often as an
//! analysis needs ([`CsvRecords`]).
//!
//! # Format
//! The CSV text of [`super::csv`]; the columns are [`Channel::column`]'s (`ax_m_s2`, …,
//! `gz_rad_s`: specific force in m/s², angular rate in rad/s), those of the three-axis study's
//! `imu.csv` (`ins::simulated_logs`).

use super::csv::read::{CsvReader, LogSource};
use super::csv::static_log::read_static_log;
use super::records::{Channel, ImuRecords, ImuSamples, Record};
use super::{LogError, LogProblem, echo};

/// The log's text, held once and lent to each column's reading under the file's name.
struct Held<'a> {
    name: &'a str,
    text: &'a [u8],
}

impl LogSource for Held<'_> {
    fn name(&self) -> &str {
        self.name
    }

    fn open(&self) -> Result<Box<dyn std::io::BufRead + '_>, LogError> {
        Ok(Box::new(self.text))
    }
}

/// The header a three-axis log is expected to have, as messages quote it.
fn expected_header() -> String {
    let columns: Vec<&str> = Channel::ALL.iter().map(|c| c.column()).collect();
    format!("t_s and any of {}", columns.join(","))
}

/// The channels `header` names, in [`Channel::ALL`]'s order.
fn channels_in(header: &str) -> Vec<Channel> {
    let found: Vec<&str> = header
        .trim_start_matches('\u{feff}')
        .split(',')
        .map(str::trim)
        .collect();
    Channel::ALL
        .into_iter()
        .filter(|c| found.contains(&c.column()))
        .collect()
}

/// Reads every channel column of the IMU log `source` (gzip read transparently; a pipe read
/// once). Each column is read and checked as `allan --accel FILE --column COLUMN` reads it, so
/// its samples are that form's, bit for bit.
///
/// # Errors
/// [`LogError`] naming the file and the line of the first problem of any column (a malformed
/// row, a field that is not a finite number, a time stamp not after the previous, a step
/// outside the accepted band), or the header when it names no channel.
pub fn read_imu_log(source: &dyn LogSource) -> Result<ImuSamples, LogError> {
    let mut text = Vec::new();
    std::io::Read::read_to_end(&mut source.open()?, &mut text).map_err(|e| {
        LogError::of_file(
            source.name(),
            LogProblem::Unreadable {
                message: e.to_string(),
            },
        )
    })?;
    let held = Held {
        name: source.name(),
        text: &text,
    };
    let header_end = memchr::memchr(b'\n', &text).unwrap_or(text.len());
    let header = String::from_utf8_lossy(&text[..header_end]);
    let present = channels_in(header.trim_end_matches('\r'));
    let Some(&first) = present.first() else {
        if text.iter().all(u8::is_ascii_whitespace) {
            // An empty file is told as the one-column reader tells it.
            read_static_log(&held, Channel::Ax.column())?;
        }
        let has_time = header.split(',').any(|f| f.trim() == "t_s");
        return Err(LogError::at(
            source.name(),
            1,
            LogProblem::MissingColumn {
                column: if has_time {
                    Channel::Ax.column()
                } else {
                    "t_s"
                },
                found: echo(header.trim()),
                header: expected_header(),
            },
        ));
    };
    let mut channels = Vec::with_capacity(present.len());
    let mut first_error: Option<LogError> = None;
    for channel in present {
        match read_static_log(&held, channel.column()) {
            Ok(s) => channels.push((channel, s)),
            // The problem on the earliest line of any column is the one told.
            Err(e) => {
                let earlier = first_error
                    .as_ref()
                    .is_none_or(|f| e.line.unwrap_or(0) < f.line.unwrap_or(0));
                if earlier {
                    first_error = Some(e);
                }
            }
        }
    }
    if let Some(e) = first_error {
        return Err(e);
    }
    let sample_period_s = channels
        .iter()
        .find(|c| c.0 == first)
        .map_or(f64::NAN, |c| c.1.sample_period_s);
    Ok(ImuSamples {
        channels: channels.into_iter().map(|(c, s)| (c, s.values)).collect(),
        sample_period_s,
    })
}

/// A CSV log of a file, read as records of its channels each time it is read
/// (`allan::imu::stream`).
pub struct CsvRecords<'a> {
    source: &'a dyn LogSource,
    channels: Vec<Channel>,
}

impl<'a> CsvRecords<'a> {
    /// The log `source` (read more than once: a file, not a pipe), its header read.
    ///
    /// # Errors
    /// [`LogError`] as [`read_imu_log`] tells a header without a channel or an empty file.
    pub fn open(source: &'a dyn LogSource) -> Result<Self, LogError> {
        let mut header = String::new();
        std::io::BufRead::read_line(&mut source.open()?, &mut header).map_err(|e| {
            LogError::of_file(
                source.name(),
                LogProblem::Unreadable {
                    message: e.to_string(),
                },
            )
        })?;
        let channels = channels_in(header.trim_end_matches(['\r', '\n']));
        if channels.is_empty() {
            // The whole-series reader tells what is wrong with the header.
            read_imu_log(source)?;
            return Err(LogError::of_file(source.name(), LogProblem::Changed));
        }
        Ok(Self { source, channels })
    }

    /// Reads with `N` columns, the time stamps' and N − 1 channels'.
    fn read_n<const N: usize>(
        &self,
        visit: &mut dyn FnMut(&Record) -> Result<(), LogError>,
    ) -> Result<(), LogError> {
        let mut columns = ["t_s"; N];
        for (c, channel) in columns[1..].iter_mut().zip(&self.channels) {
            *c = channel.column();
        }
        let mut csv = CsvReader::open(self.source, columns)?;
        while let Some((line, row)) = csv.next_row()? {
            let mut values = [0.0; 6];
            values[..N - 1].copy_from_slice(&row[1..]);
            visit(&Record {
                t_s: row[0],
                values,
                at: line,
            })?;
        }
        Ok(())
    }
}

impl ImuRecords for CsvRecords<'_> {
    fn channels(&self) -> &[Channel] {
        &self.channels
    }

    fn read(&self, visit: &mut dyn FnMut(&Record) -> Result<(), LogError>) -> Result<(), LogError> {
        match self.channels.len() {
            1 => self.read_n::<2>(visit),
            2 => self.read_n::<3>(visit),
            3 => self.read_n::<4>(visit),
            4 => self.read_n::<5>(visit),
            5 => self.read_n::<6>(visit),
            _ => self.read_n::<7>(visit),
        }
    }

    fn error_at(&self, at: u64, problem: LogProblem) -> LogError {
        LogError::at(self.source.name(), at, problem)
    }

    fn error(&self, problem: LogProblem) -> LogError {
        LogError::of_file(self.source.name(), problem)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::input::csv::read::LogText;

    #[test]
    fn any_channels_are_read_and_the_earliest_problem_is_told() {
        let text = "t_s,gz_rad_s,ax_m_s2\n0,1,2\n0.01,3,4\n0.02,5,6\n";
        let s = read_imu_log(&LogText::new("i.csv", text)).unwrap();
        assert_eq!(s.channels.len(), 2);
        assert_eq!(s.channels[0], (Channel::Ax, vec![2.0, 4.0, 6.0]));
        assert_eq!(s.channels[1], (Channel::Gz, vec![1.0, 3.0, 5.0]));
        assert_eq!(s.sample_period_s, 0.01);
        let bad = "t_s,ax_m_s2,gz_rad_s\n0,1,2\n0.01,1,nan\n0.02,x,1\n";
        let e = read_imu_log(&LogText::new("i.csv", bad)).unwrap_err();
        assert_eq!(e.line, Some(3));
        assert!(
            matches!(
                e.problem,
                LogProblem::NotFinite {
                    column: "gz_rad_s",
                    ..
                }
            ),
            "{e}"
        );
        let none = "t_s,wx\n0,1\n";
        let e = read_imu_log(&LogText::new("i.csv", none)).unwrap_err();
        assert_eq!(e.line, Some(1));
        assert!(e.to_string().contains("any of ax_m_s2"), "{e}");
        let no_time = "time,ax_m_s2\n0,1\n";
        let e = read_imu_log(&LogText::new("i.csv", no_time)).unwrap_err();
        assert!(
            matches!(e.problem, LogProblem::MissingColumn { column: "t_s", .. }),
            "{e}"
        );
        let no_time = "time,wx\n0,1\n";
        let e = read_imu_log(&LogText::new("i.csv", no_time)).unwrap_err();
        assert!(
            matches!(e.problem, LogProblem::MissingColumn { column: "t_s", .. }),
            "{e}"
        );
    }
}
