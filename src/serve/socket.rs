//! The HTTP routes and the WebSocket of `palpa serve`.
//!
//! - `GET /`, `/view.js`, `/style.css`: the page ([`super::assets`], embedded in the binary);
//! - `GET /scene.json`: the static scene ([`super::scene`]);
//! - `GET /ws`: the WebSocket. On connecting, a screen gets the current frame; then every
//!   frame of the session (broadcast to all screens), and the replies and errors of its own
//!   messages. A screen too slow for the frame rate skips to the newest frames instead of
//!   holding the others up.
//!
//! Message sizes: text longer than [`super::protocol::MAX_MESSAGE_BYTES`] gets an error reply;
//! a WebSocket message above [`WS_MAX_BYTES`] is refused by the WebSocket layer itself, which
//! closes that connection with code 1009 (message too big); other screens keep their session.

use super::protocol;
use super::session::Source;
use super::{assets, Shared};
use axum::extract::ws::{Message, WebSocket, WebSocketUpgrade};
use axum::extract::State;
use axum::http::header;
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use axum::Router;
use serde_json::json;
use std::sync::Arc;
use tokio::sync::broadcast::error::RecvError;

/// Largest WebSocket message or frame the connection accepts at all (bytes).
pub const WS_MAX_BYTES: usize = 1 << 20;

/// The server's routes.
pub fn router(shared: Arc<Shared>) -> Router {
    Router::new()
        .route(
            "/",
            get(|| async { page(assets::INDEX_HTML, "text/html; charset=utf-8") }),
        )
        .route(
            "/view.js",
            get(|| async { page(assets::VIEW_JS, "text/javascript; charset=utf-8") }),
        )
        .route(
            "/style.css",
            get(|| async { page(assets::STYLE_CSS, "text/css; charset=utf-8") }),
        )
        .route("/scene.json", get(scene))
        .route("/ws", get(upgrade))
        .with_state(shared)
}

fn page(body: &'static str, kind: &'static str) -> Response {
    (
        [
            (header::CONTENT_TYPE, kind),
            (header::CACHE_CONTROL, "no-store"),
        ],
        body,
    )
        .into_response()
}

async fn scene(State(shared): State<Arc<Shared>>) -> Response {
    (
        [
            (header::CONTENT_TYPE, "application/json"),
            (header::CACHE_CONTROL, "no-store"),
        ],
        shared.scene.clone(),
    )
        .into_response()
}

async fn upgrade(ws: WebSocketUpgrade, State(shared): State<Arc<Shared>>) -> Response {
    ws.max_message_size(WS_MAX_BYTES)
        .max_frame_size(WS_MAX_BYTES)
        .on_upgrade(move |socket| client(socket, shared))
}

fn error_text(e: &str) -> String {
    json!({"type": "error", "error": e}).to_string()
}

/// One screen's connection.
async fn client(mut socket: WebSocket, shared: Arc<Shared>) {
    let mut frames = shared.frames.subscribe();
    let first = shared.current_frame();
    if socket.send(Message::Text(first.into())).await.is_err() {
        return;
    }
    loop {
        tokio::select! {
            incoming = socket.recv() => {
                let reply = match incoming {
                    Some(Ok(Message::Text(text))) => {
                        let r = match protocol::parse(text.as_str()) {
                            Ok(msg) => {
                                let src = match msg {
                                    protocol::ClientMessage::Plate { .. } => Source::Plate,
                                    _ => Source::Pointer,
                                };
                                shared.handle(msg, src).await
                            }
                            Err(e) => Err(e),
                        };
                        match r {
                            Ok(reply) => reply,
                            Err(e) => Some(error_text(&e)),
                        }
                    }
                    Some(Ok(Message::Binary(b))) => Some(error_text(&format!(
                        "binary message of {} bytes: send JSON text messages",
                        b.len()
                    ))),
                    Some(Ok(Message::Ping(_) | Message::Pong(_))) => None,
                    Some(Ok(Message::Close(_))) | None => break,
                    Some(Err(e)) => {
                        // the WebSocket layer refused the message (too big, not UTF-8, ...):
                        // say why if the connection still takes it, then end this connection
                        let _ = socket
                            .send(Message::Text(error_text(&format!("WebSocket: {e}")).into()))
                            .await;
                        break;
                    }
                };
                if let Some(text) = reply {
                    if socket.send(Message::Text(text.into())).await.is_err() {
                        break;
                    }
                }
            }
            frame = frames.recv() => match frame {
                Ok(f) => {
                    if socket.send(Message::Text(f.as_ref().into())).await.is_err() {
                        break;
                    }
                }
                Err(RecvError::Lagged(_)) => continue,
                Err(RecvError::Closed) => break,
            },
        }
    }
}
