//! State tables as CSV: `truth.csv` and the tracker's output.
//!
//! Both start with the columns `frame,q0,q1,...,q{n-1}` (quaternion `w, x, y, z`, translation
//! in mm, joint angles in rad); the tracker's output adds report columns after them. Rows are
//! one per frame, in order, numbers as plain decimals.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use digiteyes_core::state::renormalise_quaternion;
use digiteyes_core::tracker::FrameReport;

use super::status::{Status, STATUS_COLUMN};

/// The report columns the tracker's output adds after the states.
pub const REPORT_COLUMNS: [&str; 5] = [
    "rms_px",
    "iterations",
    "features_found",
    "features_expected",
    "lost",
];

/// States read from a CSV file: `rows[k]` is the state at frame `k`.
#[derive(Debug, Clone, PartialEq)]
pub struct StateTable {
    /// One state vector per frame (quaternion, mm, rad).
    pub rows: Vec<Vec<f64>>,
    /// Names of the columns after the states (e.g. [`REPORT_COLUMNS`]).
    pub extra_columns: Vec<String>,
    /// Values of those columns, one vector per frame (`NaN` where not a number).
    pub extras: Vec<Vec<f64>>,
    /// The `status` column, one per frame, when the file has it (files written before the
    /// column existed have none); `None` for a frame whose field is empty (e.g. a frame a
    /// board dropped).
    pub status: Option<Vec<Option<Status>>>,
}

impl StateTable {
    /// The values of extra column `name`, one per frame, if the file has it.
    pub fn extra(&self, name: &str) -> Option<Vec<f64>> {
        let i = self.extra_columns.iter().position(|c| c == name)?;
        Some(self.extras.iter().map(|row| row[i]).collect())
    }

    /// Per frame, whether it claims a hand: from the `status` column when there is one
    /// (tracking), else from `lost` (0), else every frame.
    pub fn claimed(&self) -> Vec<bool> {
        if let Some(status) = &self.status {
            return status
                .iter()
                .map(|s| s.is_some_and(Status::claims_hand))
                .collect();
        }
        match self.extra("lost") {
            Some(lost) => lost.iter().map(|&v| v == 0.0).collect(),
            None => vec![true; self.rows.len()],
        }
    }
}

/// The header line `frame,q0,...,q{n-1}` (no newline).
pub fn state_header(n_states: usize) -> String {
    let mut header = String::from("frame");
    for i in 0..n_states {
        header.push_str(&format!(",q{i}"));
    }
    header
}

/// Reads a state CSV whose first columns are `frame,q0..q{n_states-1}`; later columns are
/// kept as extras. Frames must be numbered 0, 1, 2, ... in order.
pub fn read_states(path: &Path, n_states: usize) -> Result<StateTable> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    parse_states(&text, n_states).with_context(|| format!("{}", path.display()))
}

/// Parses the text of a state CSV (see [`read_states`]).
pub fn parse_states(text: &str, n_states: usize) -> Result<StateTable> {
    parse_table(text, n_states, false).map(|s| s.table)
}

/// A state CSV read by [`read_states_with_gaps`]: states that are not numbers are kept as
/// NaN, and the extra columns' text is kept too (e.g. `stream`'s `dropped` reasons).
#[derive(Debug, Clone, PartialEq)]
pub struct StatesWithGaps {
    /// The states and extra columns; a state that is not a finite number is NaN.
    pub table: StateTable,
    /// The text of every extra column (trimmed), one vector per frame.
    pub extra_text: Vec<Vec<String>>,
}

impl StatesWithGaps {
    /// The text of extra column `name`, one string per frame, if the file has it.
    pub fn extra_text(&self, name: &str) -> Option<Vec<&str>> {
        let i = self.table.extra_columns.iter().position(|c| c == name)?;
        Some(self.extra_text.iter().map(|row| row[i].as_str()).collect())
    }

    /// The frames with at least one state that is not a finite number, in order.
    pub fn gap_frames(&self) -> Vec<usize> {
        let rows = self.table.rows.iter().enumerate();
        rows.filter(|(_, row)| row.iter().any(|v| !v.is_finite()))
            .map(|(k, _)| k)
            .collect()
    }
}

/// Reads a state CSV like [`read_states`], but a state that is not a finite number (`nan`,
/// `inf`, empty, text) becomes NaN instead of an error, for reports that show such frames as
/// gaps. The header, field counts and frame numbers are checked as strictly.
pub fn read_states_with_gaps(path: &Path, n_states: usize) -> Result<StatesWithGaps> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    parse_states_with_gaps(&text, n_states).with_context(|| format!("{}", path.display()))
}

/// Parses the text of a state CSV as [`read_states_with_gaps`] reads it.
pub fn parse_states_with_gaps(text: &str, n_states: usize) -> Result<StatesWithGaps> {
    parse_table(text, n_states, true)
}

/// Parses a state CSV; with `gaps`, states that are not finite numbers become NaN.
fn parse_table(text: &str, n_states: usize, gaps: bool) -> Result<StatesWithGaps> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else {
        bail!("empty file: expected the header `frame,q0,...`")
    };
    let columns: Vec<&str> = header.split(',').map(str::trim).collect();
    let expected = state_header(n_states);
    let expected: Vec<&str> = expected.split(',').collect();
    let found_states = columns
        .iter()
        .skip(1)
        .take_while(|c| c.starts_with('q') && c[1..].parse::<usize>().is_ok())
        .count();
    if found_states != n_states && columns.first() == Some(&"frame") {
        bail!("line 1: the file has {found_states} state columns, the model has {n_states} states");
    }
    if columns.len() < expected.len() || columns[..expected.len()] != expected[..] {
        bail!(
            "line 1: header must start with `frame,q0,...,q{}`",
            n_states.saturating_sub(1)
        );
    }
    let extra_columns: Vec<String> = columns[expected.len()..]
        .iter()
        .map(|c| c.to_string())
        .collect();
    let status_at = extra_columns
        .iter()
        .position(|c| c == STATUS_COLUMN)
        .map(|i| i + n_states + 1);
    let mut table = StateTable {
        rows: Vec::new(),
        extra_columns,
        extras: Vec::new(),
        status: status_at.map(|_| Vec::new()),
    };
    let mut extra_text = Vec::new();
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
        let frame: usize = fields[0].parse().with_context(|| {
            format!(
                "line {number}: frame {} is not a number",
                crate::text::quote_value(fields[0])
            )
        })?;
        if frame != table.rows.len() {
            bail!(
                "line {number}: frame {frame} out of order, expected frame {}",
                table.rows.len()
            );
        }
        let mut state = Vec::with_capacity(n_states);
        for (i, field) in fields[1..=n_states].iter().enumerate() {
            match field.parse::<f64>() {
                // The tracker and the evaluation work in f32: a value past f32's range
                // would become infinite there, so it is refused here, naming this file.
                Ok(v) if v.is_finite() && (v as f32).is_finite() => state.push(v),
                _ if gaps => state.push(f64::NAN),
                _ => bail!(
                    "line {number}: q{i} = {} is not a finite number within f32's range",
                    crate::text::quote_value(field)
                ),
            }
        }
        let extras = fields[n_states + 1..]
            .iter()
            .map(|f| f.parse::<f64>().unwrap_or(f64::NAN))
            .collect();
        if let (Some(i), Some(column)) = (status_at, table.status.as_mut()) {
            let word = fields[i];
            let status = Status::from_word(word);
            if status.is_none() && !word.is_empty() {
                bail!(
                    "line {number}: status {} is not one of searching, tracking, lost \
                     (or empty)",
                    crate::text::quote_value(word)
                );
            }
            column.push(status);
        }
        table.rows.push(state);
        table.extras.push(extras);
        extra_text.push(
            fields[n_states + 1..]
                .iter()
                .map(|f| f.to_string())
                .collect(),
        );
    }
    Ok(StatesWithGaps { table, extra_text })
}

/// Writes `truth.csv`: the header `frame,q0..` and one row per frame.
pub fn write_truth(path: &Path, rows: &[Vec<f64>]) -> Result<()> {
    let n = rows.first().map_or(0, Vec::len);
    let mut text = state_header(n);
    text.push('\n');
    for (k, row) in rows.iter().enumerate() {
        text.push_str(&k.to_string());
        for v in row {
            text.push_str(&format!(",{v}"));
        }
        text.push('\n');
    }
    crate::atomic_file::write_atomic(path, text.as_bytes())
}

/// Writes the tracker's output CSV row by row: `frame,q0..q{n-1}` then [`REPORT_COLUMNS`].
/// The quaternion is normalised before writing; `lost` is written as 0 or 1.
///
/// The rows go to a temporary file beside `path`, renamed onto it by
/// [`StatesWriter::finish`]: a run that fails part-way leaves an existing file at `path` as
/// it was, never a partial one.
pub struct StatesWriter {
    out: crate::atomic_file::AtomicFile,
    path: PathBuf,
    n_states: usize,
    extra_columns: usize,
    frames: usize,
}

impl StatesWriter {
    /// Creates `path` and writes the header.
    pub fn create(path: &Path, n_states: usize) -> Result<Self> {
        Self::with_columns(path, n_states, &[])
    }

    /// Creates `path` and writes the header, with `extra` columns after [`REPORT_COLUMNS`]
    /// (their values are given to [`StatesWriter::write_with`]).
    pub fn with_columns(path: &Path, n_states: usize, extra: &[&str]) -> Result<Self> {
        let mut writer = StatesWriter {
            out: crate::atomic_file::AtomicFile::create(path)?,
            path: path.to_path_buf(),
            n_states,
            extra_columns: extra.len(),
            frames: 0,
        };
        let mut header = state_header(n_states);
        for c in REPORT_COLUMNS.iter().chain(extra) {
            header.push(',');
            header.push_str(c);
        }
        writer.line(&header)?;
        Ok(writer)
    }

    /// Appends the row of the next frame (extra columns, if any, left empty).
    pub fn write(&mut self, state: &[f32], report: &FrameReport) -> Result<()> {
        self.write_with(state, report, &[])
    }

    /// Appends the row of the next frame with the values of the extra columns (missing ones
    /// empty; the values must not contain commas).
    pub fn write_with(
        &mut self,
        state: &[f32],
        report: &FrameReport,
        extra: &[&str],
    ) -> Result<()> {
        if state.len() != self.n_states {
            bail!(
                "{}: state has {} values, the header {}",
                self.path.display(),
                state.len(),
                self.n_states
            );
        }
        let mut line = self.frames.to_string();
        push_states(&mut line, state);
        line.push_str(&format!(
            ",{},{},{},{},{}",
            report.rms_px,
            report.iterations,
            report.features_found,
            report.features_expected,
            u8::from(report.lost)
        ));
        for i in 0..self.extra_columns {
            let value = extra.get(i).copied().unwrap_or("");
            if value.contains([',', '\n']) {
                bail!(
                    "{}: column value `{value}` contains a comma or newline",
                    self.path.display()
                );
            }
            line.push(',');
            line.push_str(value);
        }
        self.line(&line)?;
        self.frames += 1;
        Ok(())
    }

    /// Completes the file and puts it in place at its path; returns the number of rows
    /// written. Without this, nothing is written there.
    pub fn finish(self) -> Result<usize> {
        self.out.commit()?;
        Ok(self.frames)
    }

    fn line(&mut self, line: &str) -> Result<()> {
        writeln!(self.out, "{line}")
            .with_context(|| format!("cannot write {}", self.path.display()))
    }
}

/// Appends `state` to a CSV row as `,q0,q1,…`, its quaternion normalised: how every CSV of
/// states this command writes spells them.
pub(crate) fn push_states(line: &mut String, state: &[f32]) {
    let mut state = state.to_vec();
    renormalise_quaternion(&mut state);
    for v in &state {
        line.push_str(&format!(",{v}"));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn truth_round_trips() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("truth.csv");
        let rows = vec![vec![1.0, 0.0, 0.0, 0.0, 1.5, -2.25, 600.0, 0.125]; 3];
        write_truth(&path, &rows).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.starts_with("frame,q0,q1,q2,q3,q4,q5,q6,q7\n0,1,0,0,0,1.5,-2.25,600,0.125\n"));
        let table = read_states(&path, 8).unwrap();
        assert_eq!(table.rows, rows);
        assert!(table.extra_columns.is_empty());
    }

    #[test]
    fn output_csv_has_the_documented_columns() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("states.csv");
        let mut w = StatesWriter::create(&path, 8).unwrap();
        let report = FrameReport {
            rms_px: 0.75,
            features_found: 30,
            features_expected: 35,
            iterations: 6,
            lost: true,
            ..FrameReport::default()
        };
        w.write(&[2.0, 0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 0.5], &report)
            .unwrap();
        w.write(
            &[0.0, 0.6, 0.8, 0.0, 1.0, 2.0, 3.0, 0.5],
            &FrameReport::default(),
        )
        .unwrap();
        assert_eq!(w.finish().unwrap(), 2);
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines[0],
            "frame,q0,q1,q2,q3,q4,q5,q6,q7,rms_px,iterations,features_found,features_expected,lost"
        );
        // The quaternion is written unit length.
        assert_eq!(lines[1], "0,1,0,0,0,1,2,3,0.5,0.75,6,30,35,1");
        assert_eq!(lines[2], "1,0,0.6,0.8,0,1,2,3,0.5,0,0,0,0,0");
        let table = parse_states(&text, 8).unwrap();
        assert_eq!(table.extra_columns, REPORT_COLUMNS);
        assert_eq!(table.extra("lost").unwrap(), vec![1.0, 0.0]);
        let q = &table.rows[1];
        let norm = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
        assert!((norm - 1.0).abs() < 1e-6);
    }

    #[test]
    fn malformed_tables_are_rejected_with_the_line() {
        let err = |text: &str| format!("{:#}", parse_states(text, 2).unwrap_err());
        assert!(err("").contains("empty"));
        assert!(err("frame,q0\n0,1\n").contains("1 state columns"));
        assert!(err("time,q0,q1\n").contains("header"));
        assert!(err("frame,q0,q1\n0,1\n").contains("line 2"));
        assert!(err("frame,q0,q1\n1,1,2\n").contains("expected frame 0"));
        assert!(err("frame,q0,q1\n0,1,x\n").contains("q1"));
        assert!(err("frame,q0,q1\n0,1,2\n1,1,nan\n").contains("line 3"));
    }

    #[test]
    fn the_status_column_is_read_when_present_and_checked() {
        let with =
            "frame,q0,q1,lost,status\n0,1,2,1,searching\n1,1,2,0,tracking\n2,1,2,1,lost\n3,1,2,1,\n";
        let table = parse_states(with, 2).unwrap();
        assert_eq!(
            table.status,
            Some(vec![
                Some(Status::Searching),
                Some(Status::Tracking),
                Some(Status::Lost),
                None
            ])
        );
        assert_eq!(table.claimed(), vec![false, true, false, false]);
        let without = "frame,q0,q1,lost\n0,1,2,1\n1,1,2,0\n";
        let table = parse_states(without, 2).unwrap();
        assert_eq!(table.status, None);
        assert_eq!(table.claimed(), vec![false, true]);
        let err = format!(
            "{:#}",
            parse_states("frame,q0,q1,status\n0,1,2,Tracking\n", 2).unwrap_err()
        );
        assert!(err.contains("line 2") && err.contains("Tracking"), "{err}");
    }

    #[test]
    fn gaps_are_kept_as_nan_with_the_extra_text() {
        let text = "frame,q0,q1,lost,dropped\n0,1,2,0,\n1,nan,,1,no reply (timeout)\n";
        let read = parse_table(text, 2, true).unwrap();
        assert_eq!(read.table.rows[0], vec![1.0, 2.0]);
        assert!(read.table.rows[1].iter().all(|v| v.is_nan()));
        assert_eq!(read.gap_frames(), vec![1]);
        assert_eq!(
            read.extra_text("dropped").unwrap(),
            vec!["", "no reply (timeout)"]
        );
        assert_eq!(read.table.extra("lost").unwrap(), vec![0.0, 1.0]);
        // The structure is checked as strictly as without gaps.
        assert!(parse_table("frame,q0,q1\n0,1\n", 2, true).is_err());
        assert!(parse_table("frame,q0,q1\n1,1,2\n", 2, true).is_err());
    }
}
