//! The hypotheses CSV (`track --hypotheses-out`, `stream --hypotheses-out`): every hypothesis
//! the tracker carries, frame by frame (`docs/hypotheses.md`).
//!
//! Header `frame,rank,score,age,q0,...,q{n-1}`; one row per hypothesis carried after a frame,
//! best first (`rank` 0 is the best: the state `track` outputs for that frame, written as in
//! the states CSV, quaternion normalised). `score` is the hypothesis' image likelihood less
//! the lost penalty (0 with a single hypothesis), `age` the frames it has been carried. A
//! frame with no hypothesis (searching) has no row; frames are in order, ranks 0, 1, 2, ...
//! within a frame.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use digiteyes_core::config::MAX_HYPOTHESES;
use digiteyes_core::hypotheses::Hypothesis;
use digiteyes_core::protocol::Hypotheses;

use super::states::{push_states, state_header};
use crate::text::quote_value;

/// The columns before the states.
pub const HYPOTHESES_COLUMNS: [&str; 4] = ["frame", "rank", "score", "age"];

/// The header line `frame,rank,score,age,q0,...,q{n-1}` (no newline).
pub fn hypotheses_header(n_states: usize) -> String {
    let states = state_header(n_states);
    let states = states.strip_prefix("frame").unwrap_or(&states);
    format!("{}{states}", HYPOTHESES_COLUMNS.join(","))
}

/// One row of the file: one hypothesis after one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct HypothesisRow {
    /// The frame (0-based).
    pub frame: usize,
    /// Its place among that frame's hypotheses (0: the best, the output).
    pub rank: usize,
    /// Its likelihood score less the lost penalty (0 with a single hypothesis).
    pub score: f64,
    /// Frames it has been carried (0: sampled on this frame).
    pub age: u64,
    /// Its state (quaternion, mm, rad).
    pub state: Vec<f64>,
}

/// A hypotheses CSV as read.
#[derive(Debug, Clone, PartialEq)]
pub struct HypothesesTable {
    /// The rows in file order (frames ascending, ranks ascending within a frame).
    pub rows: Vec<HypothesisRow>,
}

impl HypothesesTable {
    /// The rows of each frame `0..frames`, best first (empty for a frame with none). Rows of
    /// frames at or past `frames` are left out.
    pub fn by_frame(&self, frames: usize) -> Vec<Vec<&HypothesisRow>> {
        let mut out = vec![Vec::new(); frames];
        for row in &self.rows {
            if let Some(frame) = out.get_mut(row.frame) {
                frame.push(row);
            }
        }
        out
    }

    /// The last frame with a row, if any.
    pub fn last_frame(&self) -> Option<usize> {
        self.rows.last().map(|r| r.frame)
    }
}

/// Reads a hypotheses CSV for a model of `n_states` states; errors name the file and line.
pub fn read_hypotheses(path: &Path, n_states: usize) -> Result<HypothesesTable> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    parse_hypotheses(&text, n_states).with_context(|| format!("{}", path.display()))
}

/// Parses the text of a hypotheses CSV (see [`read_hypotheses`]): the header must be
/// [`hypotheses_header`], frames ascending, ranks 0, 1, 2, ... within a frame (fewer than
/// [`MAX_HYPOTHESES`]), every number finite.
pub fn parse_hypotheses(text: &str, n_states: usize) -> Result<HypothesesTable> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let expected = hypotheses_header(n_states);
    let Some((_, header)) = lines.next() else {
        bail!("empty file: expected the header `{expected}`")
    };
    let columns: Vec<&str> = header.split(',').map(str::trim).collect();
    if columns != expected.split(',').collect::<Vec<_>>() {
        bail!(
            "line 1: the header must be `frame,rank,score,age,q0,...,q{}` (the model has {n_states} \
             states), found {}",
            n_states.saturating_sub(1),
            quote_value(header)
        );
    }
    let mut rows: Vec<HypothesisRow> = Vec::new();
    for (index, line) in lines {
        let number = index + 1;
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != columns.len() {
            bail!(
                "line {number}: {} fields, the header has {}",
                fields.len(),
                columns.len()
            );
        }
        let whole = |i: usize| -> Result<u64> {
            fields[i].parse::<u64>().with_context(|| {
                format!(
                    "line {number}: {} {} is not a whole number",
                    columns[i],
                    quote_value(fields[i])
                )
            })
        };
        let real = |i: usize| -> Result<f64> {
            match fields[i].parse::<f64>() {
                Ok(v) if v.is_finite() && (v as f32).is_finite() => Ok(v),
                _ => bail!(
                    "line {number}: {} = {} is not a finite number within f32's range",
                    columns[i],
                    quote_value(fields[i])
                ),
            }
        };
        let frame = whole(0)? as usize;
        let rank = whole(1)? as usize;
        let expected_rank = match rows.last() {
            Some(last) if last.frame == frame => last.rank + 1,
            Some(last) if last.frame > frame => bail!(
                "line {number}: frame {frame} after frame {}: frames must ascend",
                last.frame
            ),
            _ => 0,
        };
        if rank != expected_rank {
            bail!("line {number}: rank {rank} of frame {frame}, expected rank {expected_rank}");
        }
        if rank >= MAX_HYPOTHESES {
            bail!("line {number}: rank {rank}: at most {MAX_HYPOTHESES} hypotheses per frame");
        }
        let score = real(2)?;
        let age = whole(3)?;
        let state = (4..fields.len()).map(real).collect::<Result<Vec<f64>>>()?;
        rows.push(HypothesisRow {
            frame,
            rank,
            score,
            age,
            state,
        });
    }
    Ok(HypothesesTable { rows })
}

/// Writes the hypotheses CSV frame by frame. Like the states CSV, the rows go to a temporary
/// file beside `path`, put in place by [`HypothesesWriter::finish`]: a run that fails
/// part-way leaves an existing file at `path` as it was.
pub struct HypothesesWriter {
    out: crate::atomic_file::AtomicFile,
    path: PathBuf,
    n_states: usize,
    rows: usize,
}

impl HypothesesWriter {
    /// Creates `path` and writes the header.
    pub fn create(path: &Path, n_states: usize) -> Result<Self> {
        let mut writer = HypothesesWriter {
            out: crate::atomic_file::AtomicFile::create(path)?,
            path: path.to_path_buf(),
            n_states,
            rows: 0,
        };
        writer.line(&hypotheses_header(n_states))?;
        Ok(writer)
    }

    /// Appends frame `frame`'s hypotheses, best first (none: no row).
    pub fn write_frame(&mut self, frame: usize, hypotheses: &[Hypothesis]) -> Result<()> {
        for (rank, h) in hypotheses.iter().enumerate() {
            self.write_row(frame, rank, h.score, h.age, &h.memory.state)?;
        }
        Ok(())
    }

    /// Appends the hypotheses a board sent after one frame (`BoardMessage::Hypotheses`), best
    /// first, as [`write_frame`](Self::write_frame) writes the tracker's own (none: no row).
    pub fn write_message(&mut self, message: &Hypotheses) -> Result<()> {
        let frame = message.frame as usize;
        for (rank, h) in message.hypotheses.iter().enumerate() {
            self.write_row(frame, rank, h.score, h.age, &h.q)?;
        }
        Ok(())
    }

    fn write_row(
        &mut self,
        frame: usize,
        rank: usize,
        score: f32,
        age: u32,
        state: &[f32],
    ) -> Result<()> {
        if state.len() != self.n_states {
            bail!(
                "{}: frame {frame}: a hypothesis has {} states, the header {}",
                self.path.display(),
                state.len(),
                self.n_states
            );
        }
        let mut line = format!("{frame},{rank},{score},{age}");
        push_states(&mut line, state);
        self.line(&line)?;
        self.rows += 1;
        Ok(())
    }

    /// Completes the file and puts it in place; returns the rows written.
    pub fn finish(self) -> Result<usize> {
        self.out.commit()?;
        Ok(self.rows)
    }

    fn line(&mut self, line: &str) -> Result<()> {
        writeln!(self.out, "{line}")
            .with_context(|| format!("cannot write {}", self.path.display()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_header_names_the_columns_then_the_states() {
        assert_eq!(hypotheses_header(3), "frame,rank,score,age,q0,q1,q2");
    }

    #[test]
    fn rows_are_grouped_by_frame() {
        let text = "frame,rank,score,age,q0,q1\n\
                    0,0,0.9,1,1,2\n0,1,0.8,0,1,2.5\n2,0,0.95,3,1,3\n";
        let table = parse_hypotheses(text, 2).unwrap();
        assert_eq!(table.rows.len(), 3);
        assert_eq!(table.rows[1].state, vec![1.0, 2.5]);
        assert_eq!(table.rows[2].age, 3);
        let frames = table.by_frame(3);
        assert_eq!(
            frames.iter().map(Vec::len).collect::<Vec<_>>(),
            vec![2, 0, 1]
        );
        assert_eq!(table.last_frame(), Some(2));
    }

    #[test]
    fn malformed_files_are_refused_with_the_line() {
        let err = |text: &str| format!("{:#}", parse_hypotheses(text, 2).unwrap_err());
        let head = "frame,rank,score,age,q0,q1\n";
        assert!(err("").contains("empty"));
        assert!(err("frame,q0,q1\n").contains("header"));
        assert!(err(&format!("{head}0,0,1,1,1\n")).contains("line 2"));
        assert!(err(&format!("{head}0,1,1,1,1,2\n")).contains("expected rank 0"));
        assert!(err(&format!("{head}0,0,1,1,1,2\n0,2,1,1,1,2\n")).contains("expected rank 1"));
        assert!(err(&format!("{head}1,0,1,1,1,2\n0,0,1,1,1,2\n")).contains("ascend"));
        assert!(err(&format!("{head}0,0,x,1,1,2\n")).contains("score"));
        assert!(err(&format!("{head}0,0,1,-1,1,2\n")).contains("age"));
        assert!(err(&format!("{head}0,0,1,1,1,nan\n")).contains("q1"));
        let mut many = head.to_string();
        for rank in 0..=MAX_HYPOTHESES {
            many.push_str(&format!("0,{rank},1,1,1,2\n"));
        }
        assert!(err(&many).contains("at most"));
    }
}
