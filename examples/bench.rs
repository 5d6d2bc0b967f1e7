//! Load generator for the service benchmarks (scripts/bench/run.sh).
//!
//! `bench rtt BASE N`: N sequential POST move-absolute on one keep-alive connection
//! (alternating targets, aborting), prints p50/p99/max of POST → 202 in µs.
//! `bench ws ADDR CLIENTS RATE SECONDS AXIS...`: CLIENTS websocket clients, each subscribed to
//! every AXIS status at RATE Hz, for SECONDS; prints messages received and gaps.
//! `bench reference`: the machine-speed reference every script records with its figures —
//! the planner's cycle sample (`cargo bench -p motion --bench planner`'s `step`: one sample
//! of a 100 mm jerk-limited move), median ns per call over 21 batches of 0.1 s. Figures
//! divided by it travel between machines of one kind better than absolute ones.

use std::time::{Duration, Instant};

use futures_util::{SinkExt, StreamExt};
use serde_json::json;
use tokio_tungstenite::tungstenite::Message;

fn pct(sorted: &[u64], q: f64) -> u64 {
    if sorted.is_empty() {
        return 0;
    }
    sorted[((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len()) - 1]
}

/// The planner bench's `step` (same move, limits and cycle), timed without criterion.
fn reference_ns() -> f64 {
    use motion::planner::{Kinematics, Limits, Planner};
    use std::hint::black_box;
    const CYCLE: f64 = 0.001;
    let limits = Limits {
        velocity: 100.0,
        acceleration: 1000.0,
        deceleration: 500.0,
        jerk: 10_000.0,
    };
    let mut p = Planner::new(CYCLE);
    let mut target = 100.0;
    p.plan_position(Kinematics::default(), target, 0.0, &limits)
        .unwrap();
    let mut batches = Vec::new();
    for _ in 0..21 {
        let (t, mut n) = (Instant::now(), 0u64);
        while t.elapsed() < Duration::from_millis(100) {
            for _ in 0..1000 {
                if p.finished() {
                    let from = p.end_state();
                    target = -target;
                    p.plan_position(from, target, 0.0, &limits).unwrap();
                }
                black_box(p.step(black_box(CYCLE)));
            }
            n += 1000;
        }
        batches.push(t.elapsed().as_nanos() as f64 / n as f64);
    }
    batches.sort_by(f64::total_cmp);
    batches[batches.len() / 2]
}

async fn rtt(base: &str, n: usize) {
    let client = reqwest::Client::new();
    let url = format!("{base}/api/v1/axes/y/move-absolute");
    let mut lat = Vec::with_capacity(n);
    for i in 0..n + 100 {
        let body =
            json!({"position": if i % 2 == 0 { 50.0 } else { 0.0 }, "velocity": 100.0}).to_string();
        let t = Instant::now();
        let r = client
            .post(&url)
            .header("content-type", "application/json")
            .body(body)
            .send()
            .await
            .expect("POST");
        let status = r.status().as_u16();
        let _ = r.bytes().await;
        let us = t.elapsed().as_micros() as u64;
        assert_eq!(status, 202, "POST move-absolute answered {status}");
        if i >= 100 {
            lat.push(us); // the first 100 warm up the connection and caches
        }
    }
    lat.sort_unstable();
    println!(
        "{{\"requests\": {}, \"p50_us\": {}, \"p90_us\": {}, \"p99_us\": {}, \"max_us\": {}}}",
        lat.len(),
        pct(&lat, 0.5),
        pct(&lat, 0.9),
        pct(&lat, 0.99),
        lat.last().unwrap()
    );
}

async fn ws_client(addr: String, axes: Vec<String>, rate: f64, secs: f64) -> (u64, u64, u64) {
    let (mut ws, _) = tokio_tungstenite::connect_async(format!("ws://{addr}/api/v1/ws"))
        .await
        .expect("ws connect");
    for (i, a) in axes.iter().enumerate() {
        let m = json!({"jsonrpc": "2.0", "id": i, "method": "subscribe", "params": {"topic": format!("axes/{a}/status"), "rate_hz": rate}});
        ws.send(Message::Text(m.to_string().into())).await.unwrap();
    }
    let end = Instant::now() + Duration::from_secs_f64(secs);
    let (mut updates, mut bytes, mut messages) = (0u64, 0u64, 0u64);
    while let Ok(Some(Ok(m))) = tokio::time::timeout_at(end.into(), ws.next()).await {
        if let Message::Text(t) = m {
            bytes += t.len() as u64;
            messages += 1;
            // One message per tick: the updates due together come as a JSON-RPC batch.
            updates += t.matches("\"method\":\"update\"").count() as u64;
        }
    }
    let _ = ws.close(None).await;
    (updates, bytes, messages)
}

#[tokio::main]
async fn main() {
    let args: Vec<String> = std::env::args().collect();
    match args.get(1).map(String::as_str) {
        Some("rtt") => rtt(&args[2], args[3].parse().unwrap()).await,
        Some("reference") => println!("{:.2}", reference_ns()),
        Some("ws") => {
            let addr = args[2].clone();
            let clients: usize = args[3].parse().unwrap();
            let rate: f64 = args[4].parse().unwrap();
            let secs: f64 = args[5].parse().unwrap();
            let axes: Vec<String> = args[6..].to_vec();
            let tasks: Vec<_> = (0..clients)
                .map(|_| tokio::spawn(ws_client(addr.clone(), axes.clone(), rate, secs)))
                .collect();
            let mut per_client = Vec::new();
            let (mut bytes, mut messages) = (0, 0);
            for t in tasks {
                let (u, b, m) = t.await.unwrap();
                per_client.push(u);
                bytes += b;
                messages += m;
            }
            per_client.sort_unstable();
            let total: u64 = per_client.iter().sum();
            let expected = rate * secs * axes.len() as f64;
            println!(
                "{{\"clients\": {clients}, \"axes\": {}, \"rate_hz\": {rate}, \"seconds\": {secs}, \"updates_total\": {total}, \"updates_per_s\": {:.0}, \"messages_per_s\": {:.0}, \"mb_per_s\": {:.2}, \"per_client_min\": {}, \"per_client_max\": {}, \"expected_per_client_max\": {expected:.0}}}",
                axes.len(),
                total as f64 / secs,
                messages as f64 / secs,
                bytes as f64 / secs / 1e6,
                per_client[0],
                per_client[per_client.len() - 1]
            );
        }
        _ => eprintln!(
            "usage: bench rtt BASE N | bench ws ADDR CLIENTS RATE SECONDS AXIS... | bench reference"
        ),
    }
}
