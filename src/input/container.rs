//! What a log is, told by its first bytes ([`Kind`]), and where a recording's bytes are read
//! from ([`Container`]): a file opened at each reading, or a stream (a pipe, `/dev/stdin`)
//! copied once to an anonymous temporary file ([`copy_stream`]) and read from that as often as
//! an analysis needs. A stream that is neither text nor a known container is refused at its
//! first bytes, before anything is copied.
//!
//! # Format
//! The magic bytes: MCAP's `\x89MCAP0\r\n` (mcap.dev/spec, § Magic), a ROS 1 bag's
//! `#ROSBAG V2.0\n` (wiki.ros.org/Bags/Format/2.0), gzip's `1f 8b` (RFC 1952, § 2.3.1); a CSV
//! log is UTF-8 text (RFC 3629) without control characters other than tab, CR and LF.

use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::{LogError, unreadable};

/// The first bytes of an MCAP file.
pub const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";

/// The first bytes of a ROS 1 bag.
pub const ROSBAG_MAGIC: &[u8] = b"#ROSBAG V2.0\n";

/// The two bytes that start a gzip member.
pub const GZIP_MAGIC: &[u8] = &[0x1f, 0x8b];

/// Bytes looked at to tell text from binary data.
pub const SNIFF_BYTES: usize = 4096;

/// What the first bytes of a log say it is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// An MCAP file.
    Mcap,
    /// A ROS 1 bag.
    Ros1,
    /// A gzip stream (a compressed CSV log).
    Gzip,
    /// Text, or nothing at all: read as CSV.
    Text,
    /// Neither text nor a known container.
    Binary,
}

impl Kind {
    /// The kind of a log whose first bytes are `head` (at most [`SNIFF_BYTES`] are looked at;
    /// fewer when the log is shorter).
    pub fn of(head: &[u8]) -> Kind {
        if head.starts_with(MCAP_MAGIC) {
            return Kind::Mcap;
        }
        if head.starts_with(ROSBAG_MAGIC) {
            return Kind::Ros1;
        }
        if head.starts_with(GZIP_MAGIC) {
            return Kind::Gzip;
        }
        let head = &head[..head.len().min(SNIFF_BYTES)];
        // A character cut by the end of `head` is not held against it.
        let text = match std::str::from_utf8(head) {
            Ok(_) => true,
            Err(e) => e.error_len().is_none() && e.valid_up_to() + 4 > head.len(),
        };
        let control = head
            .iter()
            .any(|&b| b < 0x20 && !matches!(b, b'\t' | b'\n' | b'\r') || b == 0x7f);
        if text && !control {
            Kind::Text
        } else {
            Kind::Binary
        }
    }

    /// The kind in words, for messages.
    pub fn words(self) -> &'static str {
        match self {
            Kind::Mcap => "an MCAP file",
            Kind::Ros1 => "a ROS 1 bag",
            Kind::Gzip => "a gzip stream",
            Kind::Text => "text",
            Kind::Binary => "binary data",
        }
    }
}

/// `head` as a message quotes it: its first 16 bytes in hexadecimal.
pub fn hex_head(head: &[u8]) -> String {
    let shown: Vec<String> = head.iter().take(16).map(|b| format!("{b:02x}")).collect();
    shown.join(" ")
}

/// The refusal of `name`, whose first bytes `head` are binary data: what was expected.
pub fn not_a_log(name: &str, head: &[u8], expected: &str) -> LogError {
    unreadable(
        name,
        format!(
            "its first bytes ({}) are neither text nor an MCAP file or a ROS 1 bag: expected \
             {expected}",
            hex_head(head)
        ),
    )
}

/// Reads up to `n` bytes from `input` (fewer only at its end).
fn read_head(input: &mut impl Read, n: usize) -> io::Result<Vec<u8>> {
    let mut head = Vec::with_capacity(n);
    input.take(n as u64).read_to_end(&mut head)?;
    Ok(head)
}

/// Copies the stream `path` (a pipe, a device) to an anonymous temporary file in `spill_dir`
/// (unlinked at creation: removed however the process ends), after its first bytes tell it is
/// text, gzip, an MCAP file or a ROS 1 bag.
///
/// # Errors
/// [`LogError`] naming `path` when it cannot be read, when its first bytes are binary data of
/// no known kind (nothing is copied then; `expected` says what was), or naming the temporary
/// file's directory when the copy cannot be made or written.
pub fn copy_stream(
    path: &Path,
    spill_dir: &Path,
    expected: &str,
) -> Result<(Kind, File), LogError> {
    let name = path.display().to_string();
    let failed = |what: &str, e: io::Error| unreadable(&name, format!("{what}: {e}"));
    let mut input = File::open(path).map_err(|e| failed("cannot be opened", e))?;
    let head = read_head(&mut input, SNIFF_BYTES).map_err(|e| failed("cannot be read", e))?;
    let kind = Kind::of(&head);
    if kind == Kind::Binary {
        return Err(not_a_log(&name, &head, expected));
    }
    let mut file = tempfile::tempfile_in(spill_dir).map_err(|e| {
        failed(
            &format!("its copy in {} cannot be made", spill_dir.display()),
            e,
        )
    })?;
    io::copy(&mut head.as_slice().chain(input), &mut file)
        .map_err(|e| failed("cannot be copied", e))?;
    Ok((kind, file))
}

/// Where a recording's bytes are: a file named by its path, or a stream's copy.
#[derive(Clone, Debug)]
pub struct Container {
    /// The name in messages: the path as the user gave it.
    name: String,
    place: Place,
}

#[derive(Clone, Debug)]
enum Place {
    Path(PathBuf),
    Copy(Arc<File>),
}

impl Container {
    /// The file at `path`.
    pub fn file(path: &Path) -> Self {
        Self {
            name: path.display().to_string(),
            place: Place::Path(path.to_path_buf()),
        }
    }

    /// The copy `file` of the stream `name`.
    pub fn copy(name: &str, file: File) -> Self {
        Self {
            name: name.to_string(),
            place: Place::Copy(Arc::new(file)),
        }
    }

    /// The name in messages.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// A reader at the start of the bytes, and their length.
    ///
    /// # Errors
    /// [`LogError`] naming the container when it cannot be opened.
    pub fn open(&self) -> Result<(At, u64), LogError> {
        let io = |e: io::Error| unreadable(&self.name, e.to_string());
        let file = match &self.place {
            Place::Path(p) => File::open(p).map_err(io)?,
            Place::Copy(f) => f.try_clone().map_err(io)?,
        };
        let len = file.metadata().map_err(io)?.len();
        Ok((At { file, at: 0 }, len))
    }
}

/// A file read by positioned reads from an offset of its own (a stream's copy is shared, its
/// offset is not).
#[derive(Debug)]
pub struct At {
    file: File,
    at: u64,
}

impl Read for At {
    fn read(&mut self, out: &mut [u8]) -> io::Result<usize> {
        let k = read_at(&self.file, out, self.at)?;
        self.at += k as u64;
        Ok(k)
    }
}

impl Seek for At {
    fn seek(&mut self, to: SeekFrom) -> io::Result<u64> {
        let target = match to {
            SeekFrom::Start(k) => Some(k),
            SeekFrom::Current(d) => self.at.checked_add_signed(d),
            SeekFrom::End(d) => self.file.metadata()?.len().checked_add_signed(d),
        };
        self.at = target.ok_or_else(|| io::Error::from(io::ErrorKind::InvalidInput))?;
        Ok(self.at)
    }
}

#[cfg(unix)]
fn read_at(file: &File, out: &mut [u8], at: u64) -> io::Result<usize> {
    std::os::unix::fs::FileExt::read_at(file, out, at)
}

#[cfg(windows)]
fn read_at(file: &File, out: &mut [u8], at: u64) -> io::Result<usize> {
    std::os::windows::fs::FileExt::seek_read(file, out, at)
}

/// The most a compressed stream is taken to expand: LZ4's format cannot pass 255 times (a
/// byte of a match's length extension stands for at most 255 bytes); bzip2 and zstd can on
/// degenerate data (a run of one byte), which a chunk of recorded messages is not.
pub const MAX_EXPANSION: u64 = 1024;

/// Bytes any compressed stream may expand to beside [`MAX_EXPANSION`] times its length (a
/// short chunk's headers and tables).
pub const EXPANSION_SLACK: u64 = 1 << 20;

/// The most bytes `compressed` bytes of compressed data are accepted to hold.
pub fn expansion_limit(compressed: u64) -> u64 {
    compressed
        .saturating_mul(MAX_EXPANSION)
        .saturating_add(EXPANSION_SLACK)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_bytes_tell_the_kind() {
        assert_eq!(Kind::of(b"\x89MCAP0\r\n\x01"), Kind::Mcap);
        assert_eq!(Kind::of(b"#ROSBAG V2.0\nxx"), Kind::Ros1);
        assert_eq!(Kind::of(&[0x1f, 0x8b, 8, 0]), Kind::Gzip);
        assert_eq!(Kind::of(b"t_s,ax_m_s2\r\n0,1\n"), Kind::Text);
        assert_eq!(Kind::of("\u{feff}t_s,é\n".as_bytes()), Kind::Text);
        assert_eq!(Kind::of(b""), Kind::Text);
        assert_eq!(Kind::of(&[0u8; 64]), Kind::Binary);
        assert_eq!(Kind::of(&[0xff, 0xfe, 0x41]), Kind::Binary);
        // A character cut at the end of what is looked at is still text.
        let mut cut = vec![b'a'; SNIFF_BYTES - 1];
        cut.extend("é".as_bytes());
        assert_eq!(Kind::of(&cut), Kind::Text);
    }
}
