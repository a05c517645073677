//! The phase of a long log kept on disk, and the overlapping Allan variance of every τ too long
//! for [`super::stream`]'s window summed from it exactly.
//!
//! # Formula
//! NIST SP 1065 (Riley 2008), eq. (11), as [`deviation::overlapping_avars`] sums it:
//! S(m) = Σ_{k=0}^{M−1} (x_{k+2m} − 2x_{k+m} + x_k)², M = n + 1 − 2m, in stretches of
//! [`STRETCH`] values of k, each stretch block by block of [`deviation::BLOCK`] terms with eight
//! running sums, the stretches added in order: the same operations in the same order as the
//! whole-series form, hence the same bits.
//!
//! The phase x_0 … x_n is written once, in order, to an anonymous temporary file (8 bytes a
//! point; `tempfile::tempfile_in`: unlinked at creation, so gone when the process ends however
//! it ends). The long factors m of the octave grid are 2^j, so the values a stretch needs sit at
//! the offsets {0} ∪ {m, 2m}: one positioned read per offset and stretch serves every long τ at
//! once (x_{k+2m} at m is x_{k+m′} at m′ = 2m), a few sequential readers over the file, memory
//! one stretch per offset.

use std::fs::File;
use std::io::{self, Write as _};
use std::path::Path;

use super::deviation::{self, BLOCK, STRETCH};

/// Phase points gathered before they are written.
const PENDING: usize = 1 << 13;

/// The phase of one channel, written point by point to a temporary file.
#[derive(Debug)]
pub struct PhaseSpill {
    file: File,
    pending: Vec<f64>,
    /// Points written or pending.
    points: usize,
    /// The first write that failed (kept until [`PhaseSpill::finish`] tells it).
    failed: Option<io::Error>,
}

impl PhaseSpill {
    /// An empty spill in a temporary file of `dir`.
    ///
    /// # Errors
    /// The [`io::Error`] of creating the file.
    pub fn create(dir: &Path) -> io::Result<Self> {
        Ok(Self {
            file: tempfile::tempfile_in(dir)?,
            pending: Vec::with_capacity(PENDING),
            points: 0,
            failed: None,
        })
    }

    /// Appends the next phase point.
    #[inline]
    pub fn push(&mut self, x: f64) {
        self.pending.push(x);
        self.points += 1;
        if self.pending.len() == PENDING {
            self.write_pending();
        }
    }

    fn write_pending(&mut self) {
        if self.failed.is_none()
            && let Err(e) = self.file.write_all(bytemuck::cast_slice(&self.pending))
        {
            self.failed = Some(e);
        }
        self.pending.clear();
    }

    /// Points pushed.
    pub fn points(&self) -> usize {
        self.points
    }

    /// Writes what is pending and tells the first write that failed.
    ///
    /// # Errors
    /// The first [`io::Error`] of writing the file (a full disk).
    pub fn finish(&mut self) -> io::Result<()> {
        self.write_pending();
        self.failed.take().map_or(Ok(()), Err)
    }

    /// Reads the points from `first` on into `out`.
    fn read_at(&self, first: usize, out: &mut [f64]) -> io::Result<()> {
        let bytes: &mut [u8] = bytemuck::cast_slice_mut(out);
        read_exact_at(&self.file, bytes, 8 * first as u64)
    }
}

#[cfg(unix)]
fn read_exact_at(file: &File, out: &mut [u8], at: u64) -> io::Result<()> {
    std::os::unix::fs::FileExt::read_exact_at(file, out, at)
}

#[cfg(windows)]
fn read_exact_at(file: &File, mut out: &mut [u8], mut at: u64) -> io::Result<()> {
    while !out.is_empty() {
        match std::os::windows::fs::FileExt::seek_read(file, out, at)? {
            0 => return Err(io::ErrorKind::UnexpectedEof.into()),
            k => {
                out = &mut out[k..];
                at += k as u64;
            }
        }
    }
    Ok(())
}

/// Σ of one block's squared second differences (x_c − 2x_b + x_a)² of the slices.
#[inline(always)]
fn block(a: &[f64], b: &[f64], c: &[f64]) -> f64 {
    deviation::block_sum_of(a, b, c)
}

/// One stretch's sums at every long factor: `buffers[o]` holds the phase from `from` +
/// `offsets[o]` on, `uses[j]` the offsets' indices (k, k + m, k + 2m) of factor j.
#[inline(always)]
fn stretch_plain(
    buffers: &[Vec<f64>],
    uses: &[[usize; 3]],
    terms: &[usize],
    from: usize,
    to: usize,
) -> Vec<f64> {
    let mut sums = vec![0.0; uses.len()];
    for start in (from..to).step_by(BLOCK) {
        for (j, u) in uses.iter().enumerate() {
            let end = (start + BLOCK).min(to).min(terms[j]);
            if start < end {
                let (s, e) = (start - from, end - from);
                let [a, b, c] = u.map(|o| &buffers[o][s..e]);
                sums[j] += block(a, b, c);
            }
        }
    }
    sums
}

crate::lanes::vectorized! {
    /// [`stretch_plain`], compiled for AVX2 when the processor has it (the same bits).
    fn stretch(buffers: &[Vec<f64>], uses: &[[usize; 3]], terms: &[usize], from: usize, to: usize) -> Vec<f64> => stretch_plain
}

/// S(m) of NIST SP 1065's eq. (11) at each factor of `factors` (powers of two) over the n + 1
/// phase points of `spill`, summed as [`deviation::overlapping_avars`] sums them.
///
/// # Errors
/// The [`io::Error`] of writing or reading the file.
pub fn second_difference_sums(spill: &mut PhaseSpill, factors: &[usize]) -> io::Result<Vec<f64>> {
    spill.finish()?;
    let points = spill.points;
    let terms: Vec<usize> = factors
        .iter()
        .map(|&m| points.saturating_sub(2 * m))
        .collect();
    let mut offsets: Vec<usize> = std::iter::once(0)
        .chain(factors.iter().flat_map(|&m| [m, 2 * m]))
        .collect();
    offsets.sort_unstable();
    offsets.dedup();
    let index = |o: usize| offsets.binary_search(&o).expect("listed");
    let uses: Vec<[usize; 3]> = factors
        .iter()
        .map(|&m| [index(0), index(m), index(2 * m)])
        .collect();
    // The k each offset is read for: the most terms among the factors using it.
    let needed: Vec<usize> = (0..offsets.len())
        .map(|o| {
            uses.iter()
                .zip(&terms)
                .filter(|(u, _)| u.contains(&o))
                .map(|(_, &t)| t)
                .max()
                .unwrap_or(0)
        })
        .collect();
    let longest = terms.iter().copied().max().unwrap_or(0);
    let mut buffers = vec![vec![0.0; STRETCH]; offsets.len()];
    let mut totals = vec![std::iter::empty::<f64>().sum::<f64>(); factors.len()];
    for from in (0..longest).step_by(STRETCH) {
        let to = (from + STRETCH).min(longest);
        for ((buffer, &o), &need) in buffers.iter_mut().zip(&offsets).zip(&needed) {
            let len = to.min(need).saturating_sub(from);
            spill.read_at(from + o, &mut buffer[..len])?;
        }
        let sums = stretch(&buffers, &uses, &terms, from, to);
        for (t, s) in totals.iter_mut().zip(sums) {
            *t += s;
        }
    }
    Ok(totals)
}
