//! The message loop over an lsp-server `Connection` (the binary makes it on stdio): the
//! initialize handshake, then each message to the [`Server`], answers and diagnostics back,
//! until `shutdown` and `exit`.

use std::collections::VecDeque;

use lsp_server::{Connection, ErrorCode, Message, RequestId, Response, ResponseError};
use lsp_types::notification::{Cancel, Notification as _};
use lsp_types::{CancelParams, NumberOrString};

use crate::server::{capabilities, Server};
use crate::Files;

/// Serves one client until it asks the server to exit after `shutdown` (`Ok`), or the
/// connection breaks or the client exits without `shutdown` (`Err`, saying which).
pub fn serve(connection: &Connection, files: Box<dyn Files>) -> Result<(), String> {
    serve_with(connection, files, None)
}

/// [`serve`], with material thumbnails in hovers.
pub fn serve_with(
    connection: &Connection,
    files: Box<dyn Files>,
    thumbnails: Option<Box<dyn crate::Thumbnails>>,
) -> Result<(), String> {
    let capabilities = serde_json::to_value(capabilities()).map_err(|e| e.to_string())?;
    connection
        .initialize(capabilities)
        .map_err(|e| format!("no `initialize` request from the client ({e})"))?;
    let mut server = Server::new(files);
    if let Some(thumbnails) = thumbnails {
        server.set_thumbnails(thumbnails);
    }
    let mut queue = VecDeque::new();
    while let Ok(first) = connection.receiver.recv() {
        // Everything already waiting is read before any analysis, so that a burst of edits
        // is compiled once, at its last version.
        queue.push_back(first);
        take_waiting(connection, &mut queue);
        while let Some(message) = queue.pop_front() {
            match message {
                Message::Request(request) => {
                    if request.method == "shutdown" {
                        return shut_down(connection, request.id, &queue);
                    }
                    // Messages that came while the last answer was made: a `$/cancelRequest`
                    // among them drops this request's work.
                    take_waiting(connection, &mut queue);
                    let (result, published) = if is_cancelled(&queue, &request.id) {
                        (Err(cancelled()), Vec::new())
                    } else {
                        answer(&mut server, request.method, request.params)
                    };
                    for notification in published {
                        send(connection, Message::Notification(notification))?;
                    }
                    let response = match result {
                        Ok(value) => Response::new_ok(request.id, value),
                        Err(error) => Response {
                            id: request.id,
                            result: None,
                            error: Some(error),
                        },
                    };
                    send(connection, Message::Response(response))?;
                }
                Message::Notification(notification) => {
                    if notification.method == "exit" {
                        // Exit without shutdown first: the protocol's error case.
                        return Err("the client sent `exit` before `shutdown`".to_string());
                    }
                    if notification.method == Cancel::METHOD {
                        // Done with: its request was answered, cancelled or never came.
                        continue;
                    }
                    let published = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                        server.notify(&notification.method, notification.params)
                    }))
                    .unwrap_or_default();
                    for notification in published {
                        send(connection, Message::Notification(notification))?;
                    }
                }
                Message::Response(_) => {}
            }
        }
        let published =
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| server.analyze_changed()))
                .unwrap_or_default();
        for notification in published {
            send(connection, Message::Notification(notification))?;
        }
    }
    Err("the client closed the connection without `exit`".to_string())
}

/// Answers `shutdown`, then waits for `exit` (it may be in the queue already: lsp-server's
/// `handle_shutdown` would wait on the channel for it).
fn shut_down(
    connection: &Connection,
    id: RequestId,
    queue: &VecDeque<Message>,
) -> Result<(), String> {
    send(connection, Message::Response(Response::new_ok(id, ())))?;
    let mut rest = queue.iter().cloned().map(Ok).chain(std::iter::from_fn(|| {
        Some(
            connection
                .receiver
                .recv_timeout(std::time::Duration::from_secs(30)),
        )
    }));
    match rest.next() {
        Some(Ok(Message::Notification(n))) if n.method == "exit" => Ok(()),
        Some(Ok(message)) => Err(format!(
            "`{message:?}` after `shutdown`, where `exit` must come"
        )),
        _ => Err("no `exit` after `shutdown`".to_string()),
    }
}

/// Appends the messages already waiting to the queue, without blocking.
fn take_waiting(connection: &Connection, queue: &mut VecDeque<Message>) {
    queue.extend(connection.receiver.try_iter());
}

/// Whether a `$/cancelRequest` for `id` is waiting in the queue (it came before the
/// request was answered).
fn is_cancelled(queue: &VecDeque<Message>, id: &RequestId) -> bool {
    queue.iter().any(|message| {
        let Message::Notification(notification) = message else {
            return false;
        };
        if notification.method != Cancel::METHOD {
            return false;
        }
        let Ok(params) = serde_json::from_value::<CancelParams>(notification.params.clone()) else {
            return false;
        };
        let cancelled = match params.id {
            NumberOrString::Number(n) => RequestId::from(n),
            NumberOrString::String(s) => RequestId::from(s),
        };
        cancelled == *id
    })
}

fn cancelled() -> ResponseError {
    ResponseError {
        code: ErrorCode::RequestCanceled as i32,
        message: "the client cancelled the request".to_string(),
        data: None,
    }
}

/// A request's answer. The server is written not to panic; should it, the one request
/// gets an internal error and the server carries on with the next.
fn answer(
    server: &mut Server,
    method: String,
    params: serde_json::Value,
) -> (
    Result<serde_json::Value, lsp_server::ResponseError>,
    Vec<lsp_server::Notification>,
) {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        server.request(&method, params)
    }))
    .unwrap_or_else(|_| {
        (
            Err(lsp_server::ResponseError {
                code: ErrorCode::InternalError as i32,
                message: format!("whitted lsp failed on `{method}` (a bug: please report it)"),
                data: None,
            }),
            Vec::new(),
        )
    })
}

fn send(connection: &Connection, message: Message) -> Result<(), String> {
    connection
        .sender
        .send(message)
        .map_err(|_| "the client is gone".to_string())
}

#[cfg(test)]
mod tests {
    use lsp_server::{Connection, Message, Notification, Request, RequestId};
    use serde_json::json;

    struct NoFiles;

    impl crate::Files for NoFiles {
        fn read(&mut self, _: &std::path::Path) -> std::io::Result<Vec<u8>> {
            Err(std::io::ErrorKind::NotFound.into())
        }
    }

    /// A request cancelled before the server reached it is answered with RequestCancelled
    /// (and nothing else); the one after it, and one whose cancel came after its answer
    /// would have been sent, are answered as usual.
    #[test]
    fn a_cancelled_request_is_answered_request_cancelled() {
        let (server, client) = Connection::memory();
        let uri = "file:///c.scene";
        let hover = json!({"textDocument": {"uri": uri}, "position": {"line": 0, "character": 10}});
        let messages = [
            Message::Request(Request::new(
                1.into(),
                "initialize".into(),
                json!({"capabilities": {}}),
            )),
            Message::Notification(Notification::new("initialized".into(), json!({}))),
            Message::Notification(Notification::new(
                "textDocument/didOpen".into(),
                json!({"textDocument": {"uri": uri, "languageId": "whitted", "version": 1,
                       "text": "sphere { radius 1 }"}}),
            )),
            Message::Request(Request::new(
                2.into(),
                "textDocument/hover".into(),
                hover.clone(),
            )),
            Message::Notification(Notification::new(
                "$/cancelRequest".into(),
                json!({"id": 2}),
            )),
            Message::Request(Request::new(
                "three".to_string().into(),
                "textDocument/hover".into(),
                hover,
            )),
            Message::Notification(Notification::new(
                "$/cancelRequest".into(),
                json!({"id": 99}),
            )),
            Message::Request(Request::new(4.into(), "shutdown".into(), json!(null))),
            Message::Notification(Notification::new("exit".into(), json!(null))),
        ];
        for message in messages {
            client.sender.send(message).expect("the channel is open");
        }
        let served = std::thread::spawn(move || super::serve(&server, Box::new(NoFiles)));
        assert_eq!(served.join().expect("no panic"), Ok(()));
        let answers: Vec<(RequestId, Option<i32>)> = client
            .receiver
            .try_iter()
            .filter_map(|message| match message {
                Message::Response(r) => Some((r.id, r.error.map(|e| e.code))),
                _ => None,
            })
            .collect();
        assert_eq!(
            answers,
            [
                (RequestId::from(1), None),
                (RequestId::from(2), Some(-32800)),
                (RequestId::from("three".to_string()), None),
                (RequestId::from(4), None),
            ]
        );
    }
}
