//! How both binaries (`voxsplat`, `voxsplat-lab`) end and print: printing to stdout that ends the
//! process quietly when stdout is a closed pipe (`voxsplat info F | head`; the standard `print!`
//! panics there), through [`print!`](crate::print) and [`println!`](crate::println), and a failed
//! command's one line on stderr ([`exit_code`]).

/// A write to stdout's outcome: a closed pipe ends the process with success (the reader has what
/// it wanted), another error with a message and failure.
pub fn stdout_or_exit(written: std::io::Result<()>) {
    match written {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => std::process::exit(0),
        Err(e) => {
            eprintln!("error: writing to stdout: {e}");
            std::process::exit(1)
        }
    }
}

/// `print!` that ends the process quietly on a closed pipe.
#[macro_export]
macro_rules! print {
    ($($arg:tt)*) => {
        $crate::stdout::stdout_or_exit(::std::io::Write::write_fmt(&mut ::std::io::stdout(), format_args!($($arg)*)))
    };
}

/// `println!` that ends the process quietly on a closed pipe.
#[macro_export]
macro_rules! println {
    ($($arg:tt)*) => {
        $crate::stdout::stdout_or_exit(::std::io::Write::write_fmt(
            &mut ::std::io::stdout(),
            format_args!("{}\n", format_args!($($arg)*)),
        ))
    };
}

/// A command's outcome as the process's exit status: success, or `error: ...` on stderr and
/// status 2 (as clap's own refusals).
pub fn exit_code(result: voxsplat::Result<()>) -> std::process::ExitCode {
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            // One write for the whole line: under mpirun the ranks share one stderr, and a line
            // written in pieces interleaves with the other ranks'.
            let line = format!("error: {e}\n");
            let _ = std::io::Write::write_all(&mut std::io::stderr(), line.as_bytes());
            std::process::ExitCode::from(2)
        }
    }
}
