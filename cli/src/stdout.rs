//! Printing to stdout that ends the process quietly when stdout is a closed pipe
//! (`voxsplat info F | head`): the standard `print!` panics there. The commands of both binaries
//! (`voxsplat`, `voxsplat-lab`) print through [`print!`](crate::print) and
//! [`println!`](crate::println).

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
