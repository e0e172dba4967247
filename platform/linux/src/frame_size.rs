//! Frame sizes as given on command lines: `WxH`.

/// Parses `WxH` (e.g. `320x240`): each side 1 to 65535 px, the range a frame's size takes on
/// the link (`u16`).
pub fn parse_frame_size(text: &str) -> Result<(u32, u32), String> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("`{text}` is not WxH, e.g. 320x240"))?;
    let parse = |s: &str| {
        s.trim()
            .parse::<u32>()
            .ok()
            .filter(|&v| (1..=u32::from(u16::MAX)).contains(&v))
            .ok_or_else(|| format!("`{s}` is not a number of pixels (1-65535)"))
    };
    Ok((parse(w)?, parse(h)?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_and_bad_ones_are_explained() {
        assert_eq!(parse_frame_size("320x240"), Ok((320, 240)));
        assert_eq!(parse_frame_size("64X48"), Ok((64, 48)));
        assert!(parse_frame_size("320").unwrap_err().contains("not WxH"));
        assert!(parse_frame_size("0x240").unwrap_err().contains("1-65535"));
        assert!(parse_frame_size("70000x2").unwrap_err().contains("1-65535"));
    }
}
