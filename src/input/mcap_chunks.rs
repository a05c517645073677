//! An MCAP file's chunks opened on all threads while their records are handed on in file order:
//! each chunk decompressed (none, lz4 or zstd) and its CRC checked on a worker of the thread
//! pool, up to [`AHEAD`] chunks ahead of the records being read. The records, their order and
//! every error are those of reading the chunks one after the other; only the time differs.
//!
//! # Format
//! MCAP (mcap.dev/spec, version 0), § Chunk: message_start_time (u64), message_end_time (u64),
//! uncompressed_size (u64), uncompressed_crc (u32, CRC-32 of the uncompressed records, 0 when
//! not computed), compression (string: "", "lz4" as an LZ4 frame, "zstd" as a Zstandard
//! frame), records (u64 length, then the compressed bytes); the records inside are the file's
//! own, an opcode (u8), a length (u64) and their data each.

use std::collections::VecDeque;
use std::ops::Range;
use std::sync::mpsc::{Receiver, sync_channel};

use super::messages::{ImuMessage, decode_imu};

/// Chunks opened ahead of the one whose records are handed on, per thread of the pool.
const AHEAD: usize = 4;

/// Compressed bytes held ahead at most: chunks are waited for beyond this, however few.
const AHEAD_BYTES: usize = 64 << 20;

/// Why a chunk cannot be read, in the words of the record it stopped at.
#[derive(Debug)]
pub(super) enum ChunkError {
    /// A record (or the chunk's decompressed records) declares more bytes than the file can
    /// hold: its opcode and its length.
    TooLarge { opcode: u8, len: u64 },
    /// Anything else, in words.
    Broken(String),
}

/// A chunk opened on the pool: its records decompressed, the buffer its record was copied to
/// (for the next), and its records sorted when asked ([`Ahead::new`]).
pub(super) struct Opened {
    /// The decompressed records, or why the chunk cannot be read.
    pub bytes: Result<Vec<u8>, ChunkError>,
    /// The buffer the chunk's record was copied to.
    pub copy: Vec<u8>,
    /// The records sorted ([`sort`]), when asked and the chunk opened.
    pub sorted: Option<Sorted>,
}

/// A message's header: channel id (u16), sequence (u32), log and publish times (u64).
pub(super) const MESSAGE_HEADER: usize = 2 + 4 + 8 + 8;

/// A piece of a chunk's records, in their order ([`sort`]).
#[derive(Debug)]
pub(super) enum Piece {
    /// Consecutive messages of one channel, each decoded as a CDR `sensor_msgs/msg/Imu`: their
    /// records' bytes (opcodes and lengths included) and their rows of [`Sorted::rows`].
    Run {
        channel: u16,
        records: Range<usize>,
        rows: Range<usize>,
    },
    /// Any other record the reader hands on (a schema, a channel, a message that is not such an
    /// `Imu`): its opcode and its data's bytes.
    Record { opcode: u8, data: Range<usize> },
    /// The chunk's records end here on this error.
    Error(ChunkError),
}

/// A chunk's records sorted on the worker that opened it: the runs of `Imu` messages decoded,
/// everything else left for the reader in order.
#[derive(Debug, Default)]
pub(super) struct Sorted {
    /// The pieces in the records' order.
    pub pieces: Vec<Piece>,
    /// The decoded messages of the runs.
    pub rows: Vec<ImuMessage>,
}

/// Sorts the decompressed records `bytes` (none longer than `limit`) into `out`: each message
/// that decodes as a CDR `Imu` joins the run of its channel's messages just before it, every
/// schema, channel or other message is a record of its own (other records are skipped: the
/// reader skips them), a broken record ends them.
pub(super) fn sort(bytes: &[u8], limit: u64, out: &mut Sorted) {
    use mcap::records::op;
    out.pieces.clear();
    out.rows.clear();
    let base = bytes.as_ptr() as usize;
    for record in records(bytes, limit) {
        let (opcode, data) = match record {
            Ok(r) => r,
            Err(e) => {
                out.pieces.push(Piece::Error(e));
                return;
            }
        };
        let start = data.as_ptr() as usize - base;
        let (head, end) = (start - 9, start + data.len());
        if opcode == op::MESSAGE && data.len() >= MESSAGE_HEADER {
            let channel = u16::from_le_bytes([data[0], data[1]]);
            if let Ok(m) = decode_imu(&data[MESSAGE_HEADER..]) {
                out.rows.push(m);
                let row = out.rows.len();
                if let Some(Piece::Run {
                    channel: c,
                    records,
                    rows,
                }) = out.pieces.last_mut()
                    && *c == channel
                {
                    records.end = end;
                    rows.end = row;
                } else {
                    out.pieces.push(Piece::Run {
                        channel,
                        records: head..end,
                        rows: row - 1..row,
                    });
                }
                continue;
            }
        }
        if matches!(opcode, op::SCHEMA | op::CHANNEL | op::MESSAGE) {
            out.pieces.push(Piece::Record {
                opcode,
                data: start..end,
            });
        }
    }
}

/// The chunk record `body` (after its opcode and length) decompressed into `out` (cleared
/// first), its CRC checked when `check_crc` and the CRC is not 0; no more than `limit` bytes
/// are decompressed.
///
/// # Errors
/// [`ChunkError::TooLarge`] when the records decompress to more than `limit` bytes,
/// [`ChunkError::Broken`] for a chunk that does not parse, an unknown compression, a
/// decompression error or a CRC that does not match.
fn open(body: &[u8], check_crc: bool, limit: u64, mut out: Vec<u8>) -> Result<Vec<u8>, ChunkError> {
    use mcap::records::Record;
    let broken = |e: &dyn std::fmt::Display| ChunkError::Broken(e.to_string());
    let Record::Chunk { header, data } =
        mcap::parse_record(mcap::records::op::CHUNK, body).map_err(|e| broken(&e))?
    else {
        return Err(broken(&"expected a chunk"));
    };
    let cap = header.uncompressed_size.min(limit);
    // One byte past the cap tells a chunk longer than it may be.
    let want = usize::try_from(cap).unwrap_or(usize::MAX).saturating_add(1);
    let read = match header.compression.as_str() {
        "" => fill(&mut &data[..], &mut out, want),
        "lz4" if lz4_whole(&data, &mut out, cap) => Ok(()),
        "lz4" => lz4::Decoder::new(&data[..]).and_then(|mut d| fill(&mut d, &mut out, want)),
        "zstd" => zstd::stream::read::Decoder::with_buffer(&data[..])
            .and_then(|mut d| fill(&mut d, &mut out, want)),
        other => {
            return Err(broken(&mcap::McapError::UnsupportedCompression(
                other.to_string(),
            )));
        }
    };
    read.map_err(|e| broken(&mcap::McapError::DecompressionError(e.to_string())))?;
    let got = out.len() as u64;
    if got > limit {
        return Err(ChunkError::TooLarge {
            opcode: mcap::records::op::CHUNK,
            len: got,
        });
    }
    if check_crc && header.uncompressed_crc != 0 {
        let calculated = crc32fast::hash(&out);
        if calculated != header.uncompressed_crc {
            return Err(broken(&mcap::McapError::BadChunkCrc {
                saved: header.uncompressed_crc,
                calculated,
            }));
        }
    }
    if got > header.uncompressed_size {
        return Err(broken(&mcap::McapError::DecompressionError(format!(
            "the chunk decompresses to more than its declared {} bytes",
            header.uncompressed_size
        ))));
    }
    Ok(out)
}

/// Room past the declared size handed to the LZ4 frame decoder: its largest block (4 MiB),
/// so that every block is decoded where it belongs. Only reserved: pages never written are
/// never touched.
const LZ4_ROOM: usize = 4 << 20;

/// The LZ4 frame `data` decompressed into `out` (cleared first) by one call of the frame
/// decoder over the whole input, into the buffer itself (the streaming decoder copies the input
/// through a 32 KiB buffer and much of the output through its own, 10 % of a read's time);
/// `true` when the frame decodes whole to at most `cap` bytes, else `false` with `out` cleared,
/// for the streaming decoder to tell what it finds (the same bytes either way).
fn lz4_whole(data: &[u8], out: &mut Vec<u8>, cap: u64) -> bool {
    use lz4::liblz4::{
        LZ4F_VERSION, LZ4F_createDecompressionContext, LZ4F_decompress,
        LZ4F_freeDecompressionContext, LZ4F_isError, LZ4FDecompressionContext,
    };
    out.clear();
    let Ok(cap) = usize::try_from(cap) else {
        return false;
    };
    let Some(room) = cap.checked_add(LZ4_ROOM) else {
        return false;
    };
    if out.try_reserve(room).is_err() {
        return false;
    }
    let mut ctx = LZ4FDecompressionContext(std::ptr::null_mut());
    // SAFETY: the context is created, used once over the input (`data.len()` bytes readable)
    // into `out`'s spare capacity (`room` bytes writable, reserved above), and freed; only
    // the bytes the decoder reports written are taken into `out`.
    unsafe {
        if LZ4F_isError(LZ4F_createDecompressionContext(&mut ctx, LZ4F_VERSION)) != 0 {
            return false;
        }
        let (mut written, mut read) = (room, data.len());
        let hint = LZ4F_decompress(
            ctx,
            out.as_mut_ptr(),
            &mut written,
            data.as_ptr(),
            &mut read,
            std::ptr::null(),
        );
        LZ4F_freeDecompressionContext(ctx);
        // A whole frame (hint 0) within the declared size; anything else is the streaming
        // decoder's to tell.
        if LZ4F_isError(hint) != 0 || hint != 0 || written > cap {
            return false;
        }
        out.set_len(written);
    }
    true
}

/// Reads `reader` to its end into `out`, at most `want` bytes. The buffer's bytes from an
/// earlier chunk are written over, not zeroed first (`read_to_end` zeroes what a reader without
/// `read_buf`, as lz4's, is handed: 6 % of a read's time); it grows by doubling, so a declared
/// size the data do not reach is never touched.
fn fill(reader: &mut dyn std::io::Read, out: &mut Vec<u8>, want: usize) -> std::io::Result<()> {
    let mut filled = 0;
    while filled < want {
        if filled == out.len() {
            let grow = filled.max(1 << 16).min(want - filled);
            out.resize(filled + grow, 0);
        }
        let end = out.len().min(want);
        match reader.read(&mut out[filled..end]) {
            Ok(0) => break,
            Ok(n) => filled += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => {
                out.truncate(filled);
                return Err(e);
            }
        }
    }
    out.truncate(filled);
    Ok(())
}

/// The records of an opened chunk in order: (opcode, data), none longer than `limit`.
///
/// # Errors
/// [`ChunkError::TooLarge`] for a record longer than `limit`, [`ChunkError::Broken`] for one
/// cut by the chunk's end (then nothing more is read).
pub(super) fn records(
    mut rest: &[u8],
    limit: u64,
) -> impl Iterator<Item = Result<(u8, &[u8]), ChunkError>> {
    std::iter::from_fn(move || {
        let (&opcode, tail) = rest.split_first()?;
        let Some((len, tail)) = tail.split_first_chunk::<8>() else {
            rest = &[];
            return Some(Err(ChunkError::Broken(
                mcap::McapError::UnexpectedEoc.to_string(),
            )));
        };
        let len = u64::from_le_bytes(*len);
        if len > limit {
            rest = &[];
            return Some(Err(ChunkError::TooLarge { opcode, len }));
        }
        let Some(data) = usize::try_from(len).ok().and_then(|n| tail.get(..n)) else {
            rest = &[];
            return Some(Err(ChunkError::Broken(
                mcap::McapError::UnexpectedEoc.to_string(),
            )));
        };
        rest = &tail[data.len()..];
        Some(Ok((opcode, data)))
    })
}

/// Chunks being opened on the pool, in file order, and the buffers of those handed on (their
/// pages used again: a fresh buffer per chunk costs its page faults every time).
pub(super) struct Ahead {
    queue: VecDeque<(usize, Receiver<Opened>)>,
    bytes: usize,
    check_crc: bool,
    limit: u64,
    /// Whether each chunk's records are sorted on the pool ([`sort`]).
    sorting: bool,
    free: Vec<Vec<u8>>,
    free_sorted: Vec<Sorted>,
}

impl Ahead {
    /// None yet; chunks will be checked against their CRC when `check_crc`, decompressed to
    /// at most `limit` bytes, and their records sorted when `sorting`.
    pub fn new(check_crc: bool, limit: u64, sorting: bool) -> Self {
        Self {
            queue: VecDeque::new(),
            bytes: 0,
            check_crc,
            limit,
            sorting,
            free: Vec::new(),
            free_sorted: Vec::new(),
        }
    }

    /// Takes back the buffers of a chunk whose records were handed on.
    pub fn recycle(&mut self, buffers: [Vec<u8>; 2], sorted: Option<Sorted>) {
        self.free.extend(buffers);
        self.free_sorted.extend(sorted);
    }

    /// Starts opening the chunk record `body` on the pool; returns the oldest chunk opened
    /// when more are ahead than [`AHEAD`] per thread (or [`AHEAD_BYTES`]), for its records to
    /// be handed on now.
    pub fn push(&mut self, body: &[u8]) -> Option<Opened> {
        let (send, receive) = sync_channel(1);
        let mut copy = self.free.pop().unwrap_or_default();
        copy.clear();
        copy.extend_from_slice(body);
        let out = self.free.pop().unwrap_or_default();
        let mut sorted = self
            .sorting
            .then(|| self.free_sorted.pop().unwrap_or_default());
        let (check_crc, limit, len) = (self.check_crc, self.limit, body.len());
        self.bytes += len;
        rayon::spawn(move || {
            let bytes = open(&copy, check_crc, limit, out);
            let sorted = match (&bytes, sorted.as_mut()) {
                (Ok(b), Some(s)) => {
                    sort(b, limit, s);
                    sorted
                }
                _ => None,
            };
            let opened = Opened {
                bytes,
                copy,
                sorted,
            };
            // The reader may have stopped at an earlier error: nobody waits then.
            let _ = send.send(opened);
        });
        self.queue.push_back((len, receive));
        let full = self.queue.len() > AHEAD * rayon::current_num_threads().max(1)
            || self.bytes > AHEAD_BYTES;
        if full { self.pop() } else { None }
    }

    /// The oldest chunk, waited for; `None` when none is ahead.
    pub fn pop(&mut self) -> Option<Opened> {
        let (len, receive) = self.queue.pop_front()?;
        self.bytes -= len;
        Some(receive.recv().unwrap_or_else(|_| {
            let e = "the worker opening the chunk ended without a result";
            Opened {
                bytes: Err(ChunkError::Broken(e.into())),
                copy: Vec::new(),
                sorted: None,
            }
        }))
    }
}
