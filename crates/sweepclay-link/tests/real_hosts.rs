//! The link against the real servers on loopback: OctoPrint 1.11 with its
//! virtual printer, and Moonraker without Klipper (`tests/hosts`).

mod hosts;

use sweepclay_link::{JobAction, Kind, Link, LinkError};

/// A short clay-like file: a square spiral of 300 moves.
fn small_gcode() -> String {
    let mut g = String::from("; a test print\nG21\nG90\nM82\nG92 E0\n");
    for i in 0..300 {
        let t = i as f64 * 0.3;
        g.push_str(&format!(
            "G1 X{:.3} Y{:.3} Z{:.3} E{:.4} F1200\n",
            100.0 + 20.0 * t.cos(),
            100.0 + 20.0 * t.sin(),
            1.0 + i as f64 * 0.01,
            i as f64 * 0.1
        ));
    }
    g
}

async fn wait_idle(link: &Link) {
    for _ in 0..600 {
        let s = link.status().await.unwrap();
        if !s.printing {
            return;
        }
        tokio::time::sleep(std::time::Duration::from_millis(200)).await;
    }
    panic!("the virtual printer did not finish in 120 s");
}

#[tokio::test(flavor = "multi_thread")]
async fn octoprint_takes_the_file_prints_it_and_names_each_failure() {
    let dir = tempfile::tempdir().unwrap();
    let Some(server) = hosts::octoprint(&dir.path().join("octoprint")) else {
        return;
    };
    let g = small_gcode();

    // A wrong key is one plain message, on every verb.
    let wrong = Link::new(Kind::OctoPrint, &server.url, Some("WRONG".into())).unwrap();
    let e = wrong
        .upload("pot", g.clone().into_bytes())
        .await
        .unwrap_err();
    assert!(matches!(e, LinkError::WrongKey { .. }), "{e}");
    assert!(e.to_string().contains("refused the API key"), "{e}");
    assert!(matches!(
        wrong.status().await,
        Err(LinkError::WrongKey { .. })
    ));

    let link = Link::new(Kind::OctoPrint, &server.url, Some(server.key.clone())).unwrap();
    let stored = link
        .upload("/some/where/pot", g.clone().into_bytes())
        .await
        .unwrap();
    assert_eq!(stored, "pot.gcode");
    assert!(link.files().await.unwrap().contains(&stored));
    let s = link.status().await.unwrap();
    assert!(s.connected && !s.printing, "{s:?}");

    link.start(&stored).await.unwrap();
    // Started: a second start is refused as busy, naming the file (the
    // virtual printer takes a few seconds for 300 lines).
    let e = link.start(&stored).await.unwrap_err();
    match &e {
        LinkError::Busy { file } => assert_eq!(file, "pot.gcode"),
        // Finished already: nothing to be busy with.
        other => assert!(matches!(other, LinkError::Busy { .. }), "{other}"),
    }
    wait_idle(&link).await;
    let s = link.status().await.unwrap();
    assert_eq!(s.progress, Some(1.0), "{s:?}");
    // Every command reached the printer, in order (the host adds its own
    // between them: temperature polls, line-number resets).
    hosts::assert_received_in_order(&server, &g);
    // And the comparison can say no: a line the file never had.
    let more = format!("{g}G1 X999 E99\n");
    assert!(std::panic::catch_unwind(|| hosts::assert_received_in_order(&server, &more)).is_err());
}

/// The state OctoPrint reports, once it is one of `want` (within 60 s).
async fn wait_state(link: &Link, want: &[&str]) -> String {
    for _ in 0..300 {
        let s = link.status().await.unwrap();
        if want.contains(&s.state.as_str()) {
            return s.state;
        }
        tokio::time::sleep(std::time::Duration::from_millis(200)).await;
    }
    panic!("OctoPrint never reached {want:?}");
}

/// Issue 59, point 3: a print sent can be paused, resumed and cancelled,
/// on the real OctoPrint's virtual printer; with nothing printing, each
/// is refused in the host's words.
#[tokio::test(flavor = "multi_thread")]
async fn octoprint_pauses_resumes_and_cancels_a_print() {
    let dir = tempfile::tempdir().unwrap();
    let Some(server) = hosts::octoprint(&dir.path().join("octoprint")) else {
        return;
    };
    let link = Link::new(Kind::OctoPrint, &server.url, Some(server.key.clone())).unwrap();
    let e = link.job(JobAction::Pause).await.unwrap_err();
    assert!(e.to_string().contains("OctoPrint"), "{e}");
    // Long enough to act on: ten times the small file.
    let g = small_gcode().repeat(10);
    let stored = link.upload("long", g.into_bytes()).await.unwrap();
    link.start(&stored).await.unwrap();
    wait_state(&link, &["Printing"]).await;
    link.job(JobAction::Pause).await.unwrap();
    wait_state(&link, &["Paused"]).await;
    let s = link.status().await.unwrap();
    assert!(s.printing, "paused is still a print under way: {s:?}");
    link.job(JobAction::Resume).await.unwrap();
    wait_state(&link, &["Printing"]).await;
    link.job(JobAction::Cancel).await.unwrap();
    wait_state(&link, &["Operational"]).await;
    let s = link.status().await.unwrap();
    assert!(!s.printing, "{s:?}");
    assert!(
        s.progress.is_none_or(|p| p < 1.0),
        "cancelled, not done: {s:?}"
    );
}

#[tokio::test(flavor = "multi_thread")]
async fn nothing_listening_is_unreachable_in_a_sentence() {
    let port = hosts::free_port();
    for kind in [Kind::OctoPrint, Kind::Moonraker, Kind::RepRap] {
        let link = Link::new(kind, &format!("http://127.0.0.1:{port}"), Some("K".into())).unwrap();
        let e = link.status().await.unwrap_err();
        assert!(matches!(e, LinkError::Unreachable { .. }), "{kind}: {e}");
        assert!(e.to_string().contains("cannot reach"), "{e}");
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn moonraker_takes_and_lists_the_file_and_says_klipper_is_missing() {
    let dir = tempfile::tempdir().unwrap();
    let Some(server) = hosts::moonraker(&dir.path().join("moonraker")) else {
        return;
    };
    let link = Link::new(Kind::Moonraker, &server.url, None).unwrap();
    let g = small_gcode();
    let stored = link
        .upload("pot.gcode", g.clone().into_bytes())
        .await
        .unwrap();
    assert_eq!(stored, "pot.gcode");
    assert!(link.files().await.unwrap().contains(&stored));
    let on_disk = std::fs::read_to_string(server.dir.join("gcodes").join("pot.gcode")).unwrap();
    assert_eq!(on_disk, g);
    // No Klipper here: the status says so, and a start is refused plainly.
    let s = link.status().await.unwrap();
    assert!(!s.connected && !s.printing, "{s:?}");
    let e = link.start(&stored).await.unwrap_err();
    assert!(matches!(e, LinkError::NotConnected { .. }), "{e}");
    assert!(e.to_string().contains("not connected"), "{e}");
    // Nor can a print be paused or cancelled without Klipper.
    for action in [JobAction::Pause, JobAction::Resume, JobAction::Cancel] {
        let e = link.job(action).await.unwrap_err();
        assert!(
            matches!(e, LinkError::NotConnected { .. }),
            "{action:?}: {e}"
        );
    }
}
