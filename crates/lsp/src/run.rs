//! The message loop over an lsp-server `Connection` (the binary makes it on stdio): the
//! initialize handshake, then each message to the [`Server`], answers and diagnostics back,
//! until `shutdown` and `exit`.

use lsp_server::{Connection, ErrorCode, Message, Response};

use crate::server::{capabilities, Server};
use crate::Files;

/// Serves one client until it asks the server to exit after `shutdown` (`Ok`), or the
/// connection breaks or the client exits without `shutdown` (`Err`, saying which).
pub fn serve(connection: &Connection, files: Box<dyn Files>) -> Result<(), String> {
    let capabilities = serde_json::to_value(capabilities()).map_err(|e| e.to_string())?;
    connection
        .initialize(capabilities)
        .map_err(|e| format!("no `initialize` request from the client ({e})"))?;
    let mut server = Server::new(files);
    while let Ok(first) = connection.receiver.recv() {
        // Everything already waiting is read before any analysis, so that a burst of edits
        // is compiled once, at its last version.
        let mut batch = vec![first];
        batch.extend(connection.receiver.try_iter());
        for message in batch {
            match message {
                Message::Request(request) => {
                    if connection
                        .handle_shutdown(&request)
                        .map_err(|e| e.to_string())?
                    {
                        return Ok(());
                    }
                    let (result, published) = answer(&mut server, request.method, request.params);
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
