//! The chosen `Imu` topic of MCAP files read in sequence (`visit_mcap`), as
//! [`Record`]s read again from disk as often as an analysis needs: record by record, or in
//! blocks whose messages were decoded on the thread pool beside the chunks' decompression.

use std::cell::{Cell, RefCell};
use std::collections::BTreeMap;

use super::container::Container;
use super::mcap::{McapEvent, Topic, visit_mcap};
use super::mcap_summary::Counts;
use super::records::{Channel, ImuRecords, Record, RecordBlock};
use super::{LogError, LogProblem, unreadable};

/// Records gathered before a block is handed on.
const BLOCK: usize = 4096;

/// One MCAP file to read: where it is, and what its summary counts (when it does).
pub(super) type McapFile = (Container, Option<Counts>);

/// The chosen `Imu` topic of MCAP files read in sequence, as records of the six channels.
pub struct McapRecords {
    /// The recording's name in messages.
    name: String,
    files: Vec<McapFile>,
    topic: String,
    /// The first message's whole second, once read.
    sec0: Cell<Option<i64>>,
    /// Whether a read went through every file: its chunks' CRCs were checked then, and are
    /// not again (13 % of a read's time).
    read_once: Cell<bool>,
    /// What the first whole read found amiss, in words.
    warnings: RefCell<Vec<String>>,
}

impl McapRecords {
    /// The `Imu` topic `topic` of `files` (the parts of the recording `name`).
    pub(super) fn new(name: String, files: Vec<McapFile>, topic: String) -> Self {
        Self {
            name,
            files,
            topic,
            sec0: Cell::new(None),
            read_once: Cell::new(false),
            warnings: RefCell::new(Vec::new()),
        }
    }

    /// The message `data` of the `Imu` topic `topic` of `file`, the `k`-th of its topic,
    /// decoded; added to `block` when the topic is the one read.
    fn decoded(
        &self,
        file: &str,
        topic: &Topic,
        data: &[u8],
        k: &mut u64,
        block: &mut RecordBlock,
    ) -> Result<(), LogError> {
        let name = topic.topic.as_str();
        let m = topic.decode(data).map_err(|e| {
            let at = format!("{file}, topic {name}, message {k}");
            unreadable(&at, e)
        })?;
        let at = *k;
        *k += 1;
        if name == self.topic {
            block.push(&m.record(&self.sec0, at));
        }
        Ok(())
    }

    /// The warning of a file whose summary counts other than `read` messages of the topic.
    fn compare(&self, file: &str, counts: &Counts, read: u64) -> Option<String> {
        let listed = counts.messages.get(&self.topic).copied()?;
        (listed != read).then(|| {
            format!(
                "{file}: its summary lists {} chunk(s) and {listed} message(s) on topic {}; {read} \
                 were read (a record of an unknown kind or a damaged part was skipped)",
                counts.chunks, self.topic
            )
        })
    }
}

impl ImuRecords for McapRecords {
    fn channels(&self) -> &[Channel] {
        &Channel::ALL
    }

    fn read(&self, visit: &mut dyn FnMut(&Record) -> Result<(), LogError>) -> Result<(), LogError> {
        // Messages per `Imu` topic: every one is decoded, as the whole-series reader does.
        let mut counts: BTreeMap<String, u64> = BTreeMap::new();
        let first = !self.read_once.get();
        for (f, summary) in &self.files {
            let before = counts.get(&self.topic).copied().unwrap_or(0);
            visit_mcap(f, (first, false), &mut |event| {
                let McapEvent::Message(topic, data) = event else {
                    return Ok(());
                };
                if !topic.is_imu() {
                    return Ok(());
                }
                let name = topic.topic.as_str();
                // A lookup by the borrowed name: no allocation per message.
                if !counts.contains_key(name) {
                    counts.insert(name.to_string(), 0);
                }
                let k = counts.get_mut(name).expect("inserted");
                let m = topic.decode(data).map_err(|e| {
                    let at = format!("{}, topic {name}, message {k}", f.name());
                    unreadable(&at, e)
                })?;
                let at = *k;
                *k += 1;
                if name != self.topic {
                    return Ok(());
                }
                visit(&m.record(&self.sec0, at))
            })?;
            let read = counts.get(&self.topic).copied().unwrap_or(0) - before;
            if first
                && let Some(w) = summary
                    .as_ref()
                    .and_then(|c| self.compare(f.name(), c, read))
            {
                self.warnings.borrow_mut().push(w);
            }
        }
        self.read_once.set(true);
        Ok(())
    }

    fn read_blocks(
        &self,
        visit: &mut dyn FnMut(&RecordBlock) -> Result<(), LogError>,
    ) -> Result<(), LogError> {
        // As `read`, the messages of each chunk's runs decoded on the pool.
        let mut counts: BTreeMap<String, u64> = BTreeMap::new();
        let first = !self.read_once.get();
        let mut block = RecordBlock::default();
        // Whether `visit` itself stopped the reading (its error is then the reading's).
        let mut stopped = false;
        for (f, summary) in &self.files {
            let before = counts.get(&self.topic).copied().unwrap_or(0);
            let read = visit_mcap(f, (first, true), &mut |event| {
                let (topic, run) = match event {
                    McapEvent::Channel(_) => return Ok(()),
                    McapEvent::Message(topic, data) => (topic, Err(data)),
                    McapEvent::Messages(topic, run) => (topic, Ok(run)),
                };
                if !topic.is_imu() {
                    return Ok(());
                }
                let name = topic.topic.as_str();
                if !counts.contains_key(name) {
                    counts.insert(name.to_string(), 0);
                }
                let k = counts.get_mut(name).expect("inserted");
                match run {
                    // Decoded on the pool as `Topic::decode` decodes a CDR message.
                    Ok(run) if topic.encoding != "ros1" => {
                        if name == self.topic {
                            for (i, m) in run.rows.iter().enumerate() {
                                block.push(&m.record(&self.sec0, *k + i as u64));
                            }
                        }
                        *k += run.rows.len() as u64;
                    }
                    Ok(run) => {
                        for data in run.payloads() {
                            self.decoded(f.name(), topic, data, k, &mut block)?;
                        }
                    }
                    Err(data) => self.decoded(f.name(), topic, data, k, &mut block)?,
                }
                if block.len() >= BLOCK {
                    let handed = visit(&block);
                    stopped = handed.is_err();
                    handed?;
                    block.clear();
                }
                Ok(())
            });
            if let Err(e) = read {
                // The records before the reading's error come first, as record by record.
                if !stopped && !block.is_empty() {
                    visit(&block)?;
                }
                return Err(e);
            }
            let read = counts.get(&self.topic).copied().unwrap_or(0) - before;
            if first
                && let Some(w) = summary
                    .as_ref()
                    .and_then(|c| self.compare(f.name(), c, read))
            {
                self.warnings.borrow_mut().push(w);
            }
        }
        if !block.is_empty() {
            visit(&block)?;
        }
        self.read_once.set(true);
        Ok(())
    }

    fn count_hint(&self) -> Option<u64> {
        self.files
            .iter()
            .map(|(_, c)| c.as_ref()?.messages.get(&self.topic).copied())
            .sum()
    }

    fn error_at(&self, at: u64, problem: LogProblem) -> LogError {
        let at = format!("{}, topic {}, message {at}", self.name, self.topic);
        LogError::of_file(&at, problem)
    }

    fn error(&self, problem: LogProblem) -> LogError {
        LogError::of_file(&format!("{}, topic {}", self.name, self.topic), problem)
    }

    fn warnings(&self) -> Vec<String> {
        self.warnings.borrow().clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A CDR `Imu` message stamped `t_ns` whose values count from `v`; `short` cuts it.
    fn imu(t_ns: u64, v: f64, short: bool) -> Vec<u8> {
        let mut b = vec![0, 1, 0, 0];
        b.extend(((t_ns / 1_000_000_000) as u32).to_le_bytes());
        b.extend(((t_ns % 1_000_000_000) as u32).to_le_bytes());
        b.extend(4u32.to_le_bytes());
        b.extend(b"imu\0");
        let mut values = [0.0; 37];
        for (k, x) in values.iter_mut().enumerate() {
            *x = v + k as f64;
        }
        values.iter().for_each(|x| b.extend(x.to_le_bytes()));
        if short {
            b.truncate(100);
        }
        b
    }

    /// An MCAP file of `n` messages on `/imu` in small chunks, one on a second `Imu` topic
    /// and one of another schema every few, message `bad` of `/imu` (if any) cut short.
    fn file(n: usize, bad: Option<usize>) -> tempfile::NamedTempFile {
        let f = tempfile::NamedTempFile::new().unwrap();
        let mut w = mcap::WriteOptions::new()
            .chunk_size(Some(3000))
            .create(std::io::BufWriter::new(f.reopen().unwrap()))
            .unwrap();
        let imu_schema = w.add_schema("sensor_msgs/msg/Imu", "ros2msg", b"").unwrap();
        let other = w.add_schema("std_msgs/msg/String", "ros2msg", b"").unwrap();
        let no_meta = Default::default();
        let ids = [
            w.add_channel(imu_schema, "/imu", "cdr", &no_meta).unwrap(),
            w.add_channel(imu_schema, "/imu2", "cdr", &no_meta).unwrap(),
            w.add_channel(other, "/text", "cdr", &no_meta).unwrap(),
        ];
        for k in 0..n {
            let t_ns = 1_700_000_000_000_000_000 + k as u64 * 2_500_000;
            let mut put = |id: u16, data: &[u8]| {
                let header = mcap::records::MessageHeader {
                    channel_id: id,
                    sequence: k as u32,
                    log_time: t_ns,
                    publish_time: t_ns,
                };
                w.write_to_known_channel(&header, data).unwrap();
            };
            put(ids[0], &imu(t_ns, k as f64, bad == Some(k)));
            if k % 7 == 3 {
                put(ids[1], &imu(t_ns, -(k as f64), false));
            }
            if k % 11 == 5 {
                put(ids[2], b"\x00\x01\x00\x00hello");
            }
        }
        w.finish().unwrap();
        f
    }

    /// Every record of `records` and the error that ends them, read record by record and in
    /// blocks.
    fn both(records: &dyn ImuRecords) -> [(Vec<String>, Option<String>); 2] {
        let mut one = Vec::new();
        let e1 = records.read(&mut |r| {
            one.push(format!("{r:?}"));
            Ok(())
        });
        let mut blocks = Vec::new();
        let e2 = records.read_blocks(&mut |b| {
            for (i, (t_s, values)) in b.t_s.iter().zip(&b.values).enumerate() {
                let at = b.at + i as u64;
                let r = Record {
                    t_s: *t_s,
                    values: *values,
                    at,
                };
                blocks.push(format!("{r:?}"));
            }
            Ok(())
        });
        [
            (one, e1.err().map(|e| e.to_string())),
            (blocks, e2.err().map(|e| e.to_string())),
        ]
    }

    #[test]
    fn blocks_are_the_records_and_the_errors_of_a_read_record_by_record() {
        for bad in [None, Some(0), Some(700), Some(1999)] {
            let f = file(2000, bad);
            let files = vec![(Container::file(f.path()), None)];
            let records = McapRecords::new("test.mcap".into(), files, "/imu".into());
            let [one, blocks] = both(&records);
            assert_eq!(one.0.len(), bad.unwrap_or(2000), "{bad:?}");
            assert_eq!(one, blocks, "{bad:?}");
            assert_eq!(one.1.is_some(), bad.is_some(), "{:?}", one.1);
        }
    }
}
