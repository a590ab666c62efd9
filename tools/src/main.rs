//! `walker-tools`: generate the DBC file and test vectors, print the bus load.

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};
use walker_tools::{generated, repo_root, splice_busload};

#[derive(Parser)]
#[command(about = "Walker workspace tools")]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Print the DBC file to stdout.
    Dbc,
    /// Print the shared test vectors (JSON) to stdout.
    Vectors,
    /// Print the bus-load table (Markdown) for the nominal message rates.
    BusLoad,
    /// Run the firmware's scripted scenarios on the host and print the per-tick trace (the
    /// QEMU binary prints the same lines; `#` lines differ and are not compared).
    Scenarios,
    /// Rewrite every generated file in the repository (DBC, test vectors, docs table).
    Gen {
        /// Only check; exit non-zero when a file is stale.
        #[arg(long)]
        check: bool,
    },
}

fn main() -> Result<()> {
    let cli = Cli::parse();
    match cli.cmd {
        Cmd::Dbc => print!("{}", protocol::dbc::render()),
        Cmd::Vectors => print!("{}", protocol::vectors::render_json()),
        Cmd::BusLoad => print!("{}", walker_tools::busload_markdown()),
        Cmd::Scenarios => {
            let mut out = String::new();
            let mut ok = true;
            for sc in firmware::scenarios::SCENARIOS {
                let summary =
                    firmware::scenarios::run(sc, &mut out, &mut firmware::scenarios::NoHook)
                        .map_err(|e| anyhow::anyhow!("{}: {e:?}", sc.name))?;
                let verdict = sc.verdict(&summary);
                ok &= verdict.is_ok();
                out.push_str(&format!("# {}: verdict {verdict:?}\n", sc.name));
            }
            print!("{out}");
            if !ok {
                bail!("a scenario failed its expectations");
            }
        }
        Cmd::Gen { check } => {
            let root = repo_root();
            let mut stale = Vec::new();
            let mut files: Vec<(String, String)> = generated()
                .into_iter()
                .map(|g| (g.path.to_string(), g.content))
                .collect();
            let doc_path = "docs/protocol.md";
            let doc = std::fs::read_to_string(root.join(doc_path))
                .with_context(|| format!("reading {doc_path}"))?;
            let Some(new_doc) = splice_busload(&doc) else {
                bail!("{doc_path}: bus-load markers missing");
            };
            files.push((doc_path.to_string(), new_doc));
            for (path, content) in files {
                let full = root.join(&path);
                let old = std::fs::read_to_string(&full).unwrap_or_default();
                if old != content {
                    stale.push(path.clone());
                    if !check {
                        std::fs::write(&full, content)
                            .with_context(|| format!("writing {path}"))?;
                        eprintln!("wrote {path}");
                    }
                }
            }
            if check && !stale.is_empty() {
                bail!("stale generated files: {stale:?}; run `cargo run -p walker-tools -- gen`");
            }
        }
    }
    Ok(())
}
