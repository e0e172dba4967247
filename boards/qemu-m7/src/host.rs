//! What the runner tells the firmware through semihosting: QEMU hands `-append TEXT` to the
//! firmware as its command line (`SYS_GET_CMDLINE`, after the ELF's path). `run-qemu` puts
//! `digiteyes-port=PATH` there when it made the PTY pair itself, so the firmware's banner can
//! name the device a host program should open.

/// The value of `digiteyes-port=` on the command line, read into `buf`; `None` when there is
/// none (QEMU run without `run-qemu`'s PTY pair) or it does not fit `buf`.
pub fn port(buf: &mut [u8]) -> Option<&str> {
    let line = cmdline(buf)?;
    line.split_ascii_whitespace()
        .find_map(|word| word.strip_prefix("digiteyes-port="))
        .filter(|path| !path.is_empty())
}

/// The semihosting command line, read into `buf`; `None` if the host gives none or it does
/// not fit.
pub fn cmdline(buf: &mut [u8]) -> Option<&str> {
    // The parameter block of SYS_GET_CMDLINE: buffer address and length; the host writes the
    // line (NUL-terminated) and replaces the length by the line's, without the NUL.
    let mut block = [buf.as_mut_ptr() as usize, buf.len()];
    #[allow(unsafe_code)]
    // SAFETY: SYS_GET_CMDLINE (0x15) takes a pointer to a two-word block: a buffer and its
    // length. Both pointers come from mutable borrows (`block`, `buf`) alive for the call,
    // and the host writes at most `buf.len()` bytes into `buf` and one word into `block`.
    // The call is a `bkpt 0xab` that QEMU (`-semihosting-config enable=on`) handles;
    // `run-qemu` always enables semihosting, and the firmware's logging needs it too.
    let status = unsafe {
        cortex_m_semihosting::syscall1(
            cortex_m_semihosting::nr::GET_CMDLINE,
            block.as_mut_ptr() as usize,
        )
    };
    let len = block[1];
    if status != 0 || len > buf.len() {
        return None;
    }
    core::str::from_utf8(buf.get(..len)?).ok()
}
