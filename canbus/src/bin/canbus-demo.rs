//! `canbus-demo`: the demonstration bus (host and two fake ankle nodes, see
//! `canbus::demo`), optionally served over socketcand and written as a candump log.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{bail, Context, Result};
use canbus::candump::CandumpWriter;
use canbus::demo::Demo;
use canbus::socketcand::{ServerConfig, SocketcandServer};
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
    /// Simulated duration [s].
    #[arg(long, default_value_t = 5.0)]
    seconds: f64,
    /// Serve the bus with the socketcand protocol on this loopback address (port 0: any free
    /// port; the address is printed on stderr as `socketcand: listening on ADDR`).
    #[arg(long, value_name = "ADDR")]
    socketcand: Option<String>,
    /// socketcand channel name.
    #[arg(long, default_value = "vcan0")]
    channel: String,
    /// With --socketcand: wait up to this long [s] for a client in rawmode before starting.
    #[arg(long, value_name = "SECONDS")]
    wait_client: Option<f64>,
    /// Write a candump log of the bus (frames, error frames, bus-off).
    #[arg(long, value_name = "FILE")]
    candump: Option<PathBuf>,
    /// Inject a fault (repeatable), e.g. `drop:id=0x072,count=5`, `busoff:node=right`.
    #[arg(long = "fault", value_name = "SPEC")]
    faults: Vec<FaultSpec>,
    /// Simulated seconds per wall-clock second; 0 = as fast as possible. Default: 1 with
    /// --socketcand, else 0.
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
    /// default 1700000000 (reproducible logs). `now` for the wall clock.
    #[arg(long, default_value = "1700000000")]
    origin: String,
    /// Print a JSON summary on stdout.
    #[arg(long)]
    json: bool,
}

fn main() -> Result<()> {
    let cli = Cli::parse();
    if !(cli.seconds.is_finite() && cli.seconds > 0.0 && cli.seconds <= 1e6) {
        bail!("--seconds {} is not in (0, 1e6]", cli.seconds);
    }
    let origin_ns = if cli.origin == "now" {
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .context("system clock before 1970")?
            .as_micros() as u64
            * 1000
    } else {
        let s: u64 = cli
            .origin
            .parse()
            .with_context(|| format!("--origin `{}`: whole seconds or `now`", cli.origin))?;
        s * 1_000_000_000
    };
    let config = BusConfig {
        bitrate_bps: cli.bitrate,
        stuffing: match cli.stuffing {
            StuffingArg::Actual => Stuffing::Actual,
            StuffingArg::Worst => Stuffing::WorstCase,
        },
        seed: cli.seed,
        ..BusConfig::default()
    };
    let mut demo = Demo::new(config, &cli.faults)?;
    let server = match &cli.socketcand {
        Some(addr) => {
            let s = SocketcandServer::bind(
                addr.as_str(),
                ServerConfig {
                    channel: cli.channel.clone(),
                    origin_ns,
                    ..ServerConfig::default()
                },
            )?;
            eprintln!("socketcand: listening on {}", s.local_addr());
            if let Some(w) = cli.wait_client {
                if !s.wait_for_client(Duration::from_secs_f64(w.max(0.0))) {
                    bail!("no socketcand client in rawmode within {w} s");
                }
                eprintln!("socketcand: client connected");
            }
            Some(s)
        }
        None => None,
    };
    let mut log = match &cli.candump {
        Some(p) => Some(CandumpWriter::new(
            BufWriter::new(File::create(p).with_context(|| format!("creating {}", p.display()))?),
            &cli.channel,
            origin_ns,
        )),
        None => None,
    };
    let speed = cli
        .speed
        .unwrap_or(if server.is_some() { 1.0 } else { 0.0 });
    let end_ns = (cli.seconds * 1e9).round() as u64;
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
            if let Some(l) = log.as_mut() {
                l.write_event(e).context("writing the candump log")?;
            }
            if let (Some(s), BusEvent::Delivered(d)) = (&server, e) {
                s.publish(&d.frame, d.t_end_ns);
            }
        }
        if speed > 0.0 && demo.now_ns() % 10_000_000 == 0 {
            let due = Duration::from_secs_f64(demo.now_ns() as f64 / 1e9 / speed);
            if let Some(wait) = due.checked_sub(wall0.elapsed()) {
                std::thread::sleep(wait);
            }
        }
    }
    let wall_s = wall0.elapsed().as_secs_f64();
    if let Some(l) = log {
        l.finish().context("writing the candump log")?;
    }
    let server_stats = server.as_ref().map(|s| {
        s.flush(Duration::from_secs(5));
        s.stats()
    });
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
            "socketcand": server_stats.map(|s| serde_json::json!({
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
