//! What every tool's command line promises: an example in each command's `--help`. The tools
//! (pend, penctl, penmodel, pen-sim) check it over all their commands with [`without_examples`].
//! And that a reader who goes away (`penmodel ridges DOC --elevations | head`) ends the tool
//! quietly, as any Unix tool: output goes through [`outln!`](crate::outln), which returns the
//! failed write instead of panicking, and `main` treats a [`broken_pipe`] as success.

/// `println!` that returns a failed write (a closed pipe) from the enclosing function, as an
/// `std::io::Error` through `?`, instead of panicking.
#[macro_export]
macro_rules! outln {
    ($($arg:tt)*) => {{
        use ::std::io::Write as _;
        writeln!(::std::io::stdout().lock(), $($arg)*)?
    }};
}

/// Whether `e` is, or was caused by, a write to a pipe whose reader went away.
pub fn broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|cause| {
        cause
            .downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

/// The commands under `command` (itself included, as `"tool sub sub"`) whose `--help` gives no
/// example: no "Example" in their after-help text.
pub fn without_examples(command: &clap::Command) -> Vec<String> {
    fn walk(c: &clap::Command, path: &str, missing: &mut Vec<String>) {
        let path = format!("{path} {}", c.get_name()).trim().to_string();
        let help = [c.get_after_help(), c.get_after_long_help()];
        if !help.iter().flatten().any(|h| h.to_string().contains("Example")) {
            missing.push(path.clone());
        }
        for sub in c.get_subcommands() {
            walk(sub, &path, missing);
        }
    }
    let mut missing = Vec::new();
    walk(command, "", &mut missing);
    missing
}

/// What each tool's tests check of its command line: well formed (clap's own checks) and an
/// example in every command's `--help`. Panics naming what is wrong.
pub fn check(command: clap::Command) {
    command.clone().debug_assert();
    let missing = without_examples(&command);
    assert!(missing.is_empty(), "no examples in the --help of {missing:?}");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_command_without_an_example_is_named() {
        let tool = clap::Command::new("tool")
            .after_help("Examples:\n  tool run")
            .subcommand(clap::Command::new("run").after_long_help("Example: tool run"))
            .subcommand(clap::Command::new("bare"));
        assert_eq!(without_examples(&tool), ["tool bare"]);
    }
}
