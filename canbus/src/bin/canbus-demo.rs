//! `canbus-demo`: the demonstration bus (host and two fake ankle nodes, see
//! `canbus::demo`), optionally served over socketcand and written as a candump log.
//!
//! Exit codes: 0 on success, 2 for bad input (a message names the option and its value), 1
//! for any other error (no socketcand client in time, a failing write).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::{bail, Context, Result};
use canbus::candump::CandumpWriter;
use canbus::demo::{Demo, TICK_NS};
use canbus::protocol_ids::check_fault_id;
use canbus::socketcand::{ServerConfig, SocketcandServer};
use canbus::timestamp::stamp_ns;
use canbus::wait_client::wait_client_timeout;
use canbus::{BusConfig, BusEvent, FaultSpec, Stuffing};
use clap::{Parser, ValueEnum};

#[derive(Clone, Copy, Debug, ValueEnum)]
enum StuffingArg {
    Actual,
    Worst,
}

#[derive(Parser, Debug)]
#[command(about = "Simulated walker CAN bus: a host and two fake ankle nodes at nominal rates")]
struct Cli {
    /// Simulated duration \[s\].
    #[arg(long, default_value_t = 5.0)]
    seconds: f64,
    /// Serve the bus with the socketcand protocol on this loopback address (port 0: any free
    /// port; the address is printed on stderr as `socketcand: listening on ADDR`).
    #[arg(long, value_name = "ADDR")]
    socketcand: Option<String>,
    /// socketcand channel name.
    #[arg(long, default_value = "vcan0")]
    channel: String,
    /// With --socketcand: wait up to this long \[s\] for a client in rawmode before starting
    /// (0 to 86400).
    #[arg(long, value_name = "SECONDS")]
    wait_client: Option<f64>,
    /// With --socketcand: put frames the clients send on the bus as the host's (a control
    /// channel for any local process). Without it the server is read-only and refuses them.
    #[arg(long)]
    socketcand_allow_send: bool,
    /// Write a candump log of the bus (frames, error frames, bus-off).
    #[arg(long, value_name = "FILE")]
    candump: Option<PathBuf>,
    /// Inject a fault (repeatable), e.g. `drop:id=0x072,count=5`, `busoff:node=right`.
    #[arg(long = "fault", value_name = "SPEC")]
    faults: Vec<FaultSpec>,
    /// Simulated seconds per wall-clock second (0.001 to 1e6); 0 = as fast as possible.
    /// Default: 1 with --socketcand, else 0.
    #[arg(long)]
    speed: Option<f64>,
    /// Bit rate [bit/s].
    #[arg(long, default_value_t = protocol::BITRATE_BPS)]
    bitrate: u32,
    /// Stuff-bit model.
    #[arg(long, value_enum, default_value = "actual")]
    stuffing: StuffingArg,
    /// Seed of the fault RNG.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Timestamp origin [s since the Unix epoch] added to simulated time in logs and frames;
    /// default 1700000000 (reproducible logs). `now` for the wall clock. The last timestamp
    /// must fit in u64 nanoseconds (before 18446744073.709551615 s).
    #[arg(long, default_value = "1700000000")]
    origin: String,
    /// Print a JSON summary on stdout.
    #[arg(long)]
    json: bool,
}

/// Bad input: the message names the option and its value; exit code 2.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
struct InputError(String);

fn input(msg: String) -> anyhow::Error {
    InputError(msg).into()
}

/// Slowest and fastest --speed other than 0.
const SPEED_RANGE: (f64, f64) = (1e-3, 1e6);
/// Bit rates accepted [bit/s]: classic CAN's range (ISO 11898-2 high speed up to 1 Mbit/s;
/// 10 kbit/s is the slowest rate CiA 301 lists). At 1 bit/s a single frame outlasts any run
/// and the load read 0.00 %.
const BITRATE_RANGE_BPS: (u32, u32) = (10_000, 1_000_000);

/// How long the end of a run waits for socketcand clients to read what is queued.
const FLUSH_TIMEOUT: Duration = Duration::from_millis(500);

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(&cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            if e.downcast_ref::<InputError>().is_some() {
                ExitCode::from(2)
            } else {
                ExitCode::from(1)
            }
        }
    }
}

/// The timestamp origin [ns since the Unix epoch] of `--origin`.
fn origin_ns(origin: &str) -> Result<u64> {
    if origin == "now" {
        let since = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .context("system clock before 1970")?;
        return u64::try_from(since.as_micros())
            .ok()
            .and_then(|us| us.checked_mul(1000))
            .context("the system clock is past the latest u64 nanosecond timestamp");
    }
    let s: u64 = origin.parse().map_err(|_| {
        input(format!(
            "--origin `{origin}`: expected whole seconds since the Unix epoch or `now`"
        ))
    })?;
    s.checked_mul(1_000_000_000).ok_or_else(|| {
        input(format!(
            "--origin {origin}: later than the latest u64 nanosecond timestamp (18446744073 s)"
        ))
    })
}

/// The checked options: (end of the run \[ns\], origin \[ns\], speed, wait for a client).
struct Checked {
    end_ns: u64,
    origin_ns: u64,
    speed: f64,
    wait_client: Option<Duration>,
}

fn check(cli: &Cli) -> Result<Checked> {
    if !(cli.seconds.is_finite() && cli.seconds > 0.0 && cli.seconds <= 1e6) {
        return Err(input(format!(
            "--seconds {:?} is not in (0, 1e6]",
            cli.seconds
        )));
    }
    if cli.channel.is_empty()
        || cli.channel.len() > 64
        || cli
            .channel
            .chars()
            .any(|c| c.is_whitespace() || c == '<' || c == '>')
    {
        return Err(input(format!(
            "--channel `{}`: expected 1 to 64 characters without spaces, `<` or `>`",
            cli.channel
        )));
    }
    let speed = cli
        .speed
        .unwrap_or(if cli.socketcand.is_some() { 1.0 } else { 0.0 });
    if !(speed == 0.0 || (speed >= SPEED_RANGE.0 && speed <= SPEED_RANGE.1)) {
        return Err(input(format!(
            "--speed {speed:?}: expected 0 (as fast as possible) or a factor in [{}, {}]",
            SPEED_RANGE.0, SPEED_RANGE.1
        )));
    }
    if cli.socketcand.is_none() {
        for (given, flag) in [
            (cli.wait_client.is_some(), "--wait-client"),
            (cli.socketcand_allow_send, "--socketcand-allow-send"),
        ] {
            if given {
                return Err(input(format!("{flag} needs --socketcand ADDR")));
            }
        }
    }
    if !(BITRATE_RANGE_BPS.0..=BITRATE_RANGE_BPS.1).contains(&cli.bitrate) {
        return Err(input(format!(
            "--bitrate {}: expected a classic CAN bit rate from {} to {} bit/s",
            cli.bitrate, BITRATE_RANGE_BPS.0, BITRATE_RANGE_BPS.1
        )));
    }
    let wait_client = match cli.wait_client {
        None => None,
        Some(w) => Some(wait_client_timeout(w).map_err(input)?),
    };
    let end_ns = (cli.seconds * 1e9).round() as u64;
    let origin_ns = origin_ns(&cli.origin)?;
    // the last event ends with the last tick
    let last_ns = end_ns.div_ceil(TICK_NS) * TICK_NS;
    stamp_ns(origin_ns, last_ns).map_err(|e| {
        input(format!(
            "--origin {} with --seconds {}: {e}",
            cli.origin, cli.seconds
        ))
    })?;
    Ok(Checked {
        end_ns,
        origin_ns,
        speed,
        wait_client,
    })
}

fn candump_context(p: &Path) -> String {
    format!("writing the candump log {}", p.display())
}

fn run(cli: &Cli) -> Result<()> {
    let Checked {
        end_ns,
        origin_ns,
        speed,
        wait_client,
    } = check(cli)?;
    let config = BusConfig {
        bitrate_bps: cli.bitrate,
        stuffing: match cli.stuffing {
            StuffingArg::Actual => Stuffing::Actual,
            StuffingArg::Worst => Stuffing::WorstCase,
        },
        seed: cli.seed,
        ..BusConfig::default()
    };
    for f in &cli.faults {
        check_fault_id(f).map_err(|e| input(format!("--fault `{f}`: {e}")))?;
    }
    let mut demo = Demo::new(config, &cli.faults).map_err(|e| input(e.to_string()))?;
    let mut log =
        match &cli.candump {
            Some(p) => Some(CandumpWriter::new(
                BufWriter::new(File::create(p).map_err(|e| {
                    input(format!("--candump {}: creating the log: {e}", p.display()))
                })?),
                &cli.channel,
                origin_ns,
            )),
            None => None,
        };
    let server = match &cli.socketcand {
        Some(addr) => {
            let s = SocketcandServer::bind(
                addr.as_str(),
                ServerConfig {
                    channel: cli.channel.clone(),
                    origin_ns,
                    allow_send: cli.socketcand_allow_send,
                    ..ServerConfig::default()
                },
            )
            .map_err(|e| input(format!("--socketcand {addr}: {e}")))?;
            eprintln!("socketcand: listening on {}", s.local_addr());
            eprintln!(
                "socketcand: {}",
                if cli.socketcand_allow_send {
                    "clients may send frames onto the bus (--socketcand-allow-send)"
                } else {
                    "read-only (frames from clients are refused; --socketcand-allow-send to accept them)"
                }
            );
            if let Some(w) = wait_client {
                if !s.wait_for_client(w) {
                    bail!(
                        "no socketcand client in rawmode within {} s",
                        w.as_secs_f64()
                    );
                }
                eprintln!("socketcand: client connected");
            }
            Some(s)
        }
        None => None,
    };
    let wall0 = Instant::now();
    let mut events_total = 0u64;
    while demo.now_ns() < end_ns {
        if let Some(s) = &server {
            for f in s.take_inbound() {
                demo.send_from_host(f)?;
            }
        }
        let events = demo.tick()?;
        events_total += events.len() as u64;
        for e in &events {
            if let (Some(l), Some(p)) = (log.as_mut(), &cli.candump) {
                l.write_event(e).with_context(|| candump_context(p))?;
            }
            if let (Some(s), BusEvent::Delivered(d)) = (&server, e) {
                s.publish(&d.frame, d.t_end_ns)
                    .context("serving a frame over socketcand")?;
            }
        }
        if speed > 0.0 && demo.now_ns() % 10_000_000 == 0 {
            let due = Duration::try_from_secs_f64(demo.now_ns() as f64 / 1e9 / speed)
                .with_context(|| format!("pacing at --speed {speed}"))?;
            if let Some(wait) = due.checked_sub(wall0.elapsed()) {
                std::thread::sleep(wait);
            }
        }
    }
    let wall_s = wall0.elapsed().as_secs_f64();
    if let (Some(l), Some(p)) = (log, &cli.candump) {
        l.finish().with_context(|| candump_context(p))?;
    }
    let server_stats = server.as_ref().map(|s| (s.flush(FLUSH_TIMEOUT), s.stats()));
    drop(server);
    let stats = demo.bus.stats();
    let sim_s = demo.now_ns() as f64 / 1e9;
    if cli.json {
        let j = serde_json::json!({
            "simulated_s": sim_s,
            "wall_s": wall_s,
            "speedup": if wall_s > 0.0 { sim_s / wall_s } else { f64::INFINITY },
            "events": events_total,
            "faults": cli.faults.iter().map(|f| f.to_string()).collect::<Vec<_>>(),
            "bus": stats,
            "socketcand": server_stats.map(|(flushed, s)| serde_json::json!({
                "flushed": flushed,
                "clients_refused": s.clients_refused,
                "clients_stalled": s.clients_stalled,
                "inbound_dropped": s.inbound_dropped,
                "clients_accepted": s.clients_accepted,
                "frames_sent": s.frames_sent,
                "frames_dropped": s.frames_dropped,
                "frames_received": s.frames_received,
                "bad_commands": s.bad_commands,
            })),
        });
        let mut out = std::io::stdout().lock();
        serde_json::to_writer_pretty(&mut out, &j)?;
        writeln!(out)?;
    } else {
        if let Some((_, s)) = server_stats {
            eprintln!(
                "socketcand: {} clients, {} frames sent, {} dropped (full client queues), {} clients refused, {} stalled",
                s.clients_accepted, s.frames_sent, s.frames_dropped, s.clients_refused, s.clients_stalled
            );
        }
        eprintln!(
            "{sim_s:.3} s simulated in {wall_s:.3} s: {} frames, {} error frames, {} dropped, {} queue overflows, bus load {:.2} %",
            stats.frames,
            stats.error_frames,
            stats.dropped,
            stats.queue_overflows,
            100.0 * stats.load
        );
    }
    Ok(())
}
