//! Over a real server, in a process of its own (the test measures the
//! process's CPU, which other tests running beside it would add to): a
//! request whose client goes away stops its work.

mod common;
use common::{post, server};
use sweepclay_core::examples;
use sweepclay_web::api::Limits;

/// CPU seconds this process has used (user and system, from
/// `/proc/self/stat`, in clock ticks of 1/100 s).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap();
    // Fields after the command name in parentheses: utime is the 14th
    // field of the line, stime the 15th.
    let rest = &stat[stat.rfind(')').unwrap() + 2..];
    let f: Vec<&str> = rest.split(' ').collect();
    (f[11].parse::<f64>().unwrap() + f[12].parse::<f64>().unwrap()) / 100.0
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_client_that_goes_away_stops_its_work() {
    use tokio::io::AsyncWriteExt;
    let base = server(Limits::default()).await;
    let body = examples::scaled(1_000_000).to_json();
    // How long the G-code of this design takes when its client waits.
    let t = std::time::Instant::now();
    let cpu = cpu_seconds();
    let r = post(&format!("{base}/api/gcode"), body.clone()).await;
    assert_eq!(r.status(), 200);
    let _ = r.bytes().await.unwrap();
    let (full, full_cpu) = (t.elapsed().as_secs_f64(), cpu_seconds() - cpu);
    assert!(full_cpu > 0.5, "{full} s, {full_cpu} s of CPU");
    // The same request, its client gone a fifth of the way in: the work
    // stops at the next stage or G-code chunk, so over the rest of the
    // time it would have taken the process is all but idle.
    let addr = base.trim_start_matches("http://");
    let mut s = tokio::net::TcpStream::connect(addr).await.unwrap();
    let head = format!(
        "POST /api/gcode HTTP/1.1\r\nHost: {addr}\r\nContent-Type: application/json\r\nContent-Length: {}\r\n\r\n",
        body.len()
    );
    s.write_all(head.as_bytes()).await.unwrap();
    s.write_all(body.as_bytes()).await.unwrap();
    tokio::time::sleep(std::time::Duration::from_secs_f64(full / 5.0)).await;
    drop(s);
    // A stage may still run to its end (at most about a third of the job).
    tokio::time::sleep(std::time::Duration::from_secs_f64(full / 3.0)).await;
    let cpu = cpu_seconds();
    tokio::time::sleep(std::time::Duration::from_secs_f64(full / 3.0)).await;
    let after = cpu_seconds() - cpu;
    assert!(
        after < 0.25 * full_cpu / 3.0 + 0.05,
        "{after} s of CPU in the last third of a {full} s job ({full_cpu} s of CPU) after its client left"
    );
}
