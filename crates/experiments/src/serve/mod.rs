//! The browser material editor of `experiments serve` (§5.1's edits, interactively):
//! one axum router serving one embedded page ([`PAGE`], no external scripts or fonts) and a
//! small JSON API over the [`editor`] worker. [`request`] checks what the page sends.
//!
//! | route | what |
//! | --- | --- |
//! | `GET /` | the page |
//! | `GET /api/info` | the model and the bundled material ids |
//! | `POST /api/open` `{"material": ID}` | a material's attributes and latent |
//! | `POST /api/upload?name=FILE` (the file as the body) | reads a `.binary` / `.bsdf` upload |
//! | `POST /api/original` `{"material": ID, "scene": ..}` | PNG of the original |
//! | `POST /api/preview` `{"edit": .., "quality": "fast"/"refined"}` | the edited preview |
//! | `GET /api/download?format=binary/bsdf/latent&edit=JSON` | the edited `.binary`, RGL `.bsdf` or latent file |
//!
//! Bad input is answered 4xx with a text message (400 bad values or files, 404 unknown
//! materials, 409 a preview superseded by a newer one, 413 an oversized body); nothing a
//! request names is read from or written to disk except the server's cache (bundled materials
//! are named by id, uploads are parsed in memory).
pub mod editor;
pub mod launch;
mod queue;
mod recent;
mod replies;
pub mod request;

use axum::body::Body;
use axum::extract::rejection::{JsonRejection, QueryRejection};
use axum::extract::{DefaultBodyLimit, Query, State};
use axum::http::{header, HeaderMap, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::{Json, Router};
use base64::Engine as _;
use editor::{Download, EditorHandle, Failure};
use request::{EditRequest, PreviewRequest, Refusal, SceneChoice};
use serde::Deserialize;

/// The page: HTML, CSS and JS in one file.
pub const PAGE: &str = include_str!("page.html");
/// Largest upload accepted: a MERL file is 34,992,012 bytes; the RGL measurements are smaller.
pub const UPLOAD_LIMIT: usize = 64 << 20;
/// Largest body of the other requests.
pub const JSON_LIMIT: usize = 64 << 10;

/// A refused or failed request.
struct ApiError(StatusCode, String);

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        let mut r = (self.0, self.1).into_response();
        r.headers_mut()
            .insert(header::CONTENT_TYPE, HeaderValue::from_static("text/plain; charset=utf-8"));
        r
    }
}

impl From<Refusal> for ApiError {
    fn from(r: Refusal) -> Self {
        match r {
            Refusal::BadRequest(m) => Self(StatusCode::BAD_REQUEST, m),
            Refusal::NotFound(m) => Self(StatusCode::NOT_FOUND, m),
        }
    }
}

impl From<Failure> for ApiError {
    fn from(f: Failure) -> Self {
        match f {
            Failure::Refused(r) => r.into(),
            Failure::Superseded => {
                Self(StatusCode::CONFLICT, "superseded by a newer preview".into())
            }
            Failure::Internal(m) => {
                log::warn!("request failed: {m}");
                Self(StatusCode::INTERNAL_SERVER_ERROR, m)
            }
        }
    }
}

fn json_error(e: JsonRejection) -> ApiError {
    ApiError(StatusCode::BAD_REQUEST, format!("malformed request: {}", e.body_text()))
}

type ApiResult<T> = Result<T, ApiError>;

/// The router of the editor.
pub fn router(editor: EditorHandle) -> Router {
    Router::new()
        .route("/", get(page))
        .route("/api/info", get(info))
        .route("/api/open", post(open))
        .route("/api/upload", post(upload).layer(DefaultBodyLimit::max(UPLOAD_LIMIT)))
        .route("/api/original", post(original))
        .route("/api/preview", post(preview))
        .route("/api/download", get(download))
        .layer(DefaultBodyLimit::max(JSON_LIMIT))
        .with_state(editor)
}

async fn page() -> Response {
    let mut r = axum::response::Html(PAGE).into_response();
    // Nothing from elsewhere: scripts, styles and images come from the page and this server.
    r.headers_mut().insert(
        header::CONTENT_SECURITY_POLICY,
        HeaderValue::from_static(
            "default-src 'self'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; \
             img-src 'self' data: blob:",
        ),
    );
    r
}

async fn info(State(editor): State<EditorHandle>) -> Response {
    let materials: Vec<&String> = editor.catalogue.bundled().collect();
    Json(serde_json::json!({
        "model": *editor.model,
        "materials": materials,
        "upload_limit": UPLOAD_LIMIT,
    }))
    .into_response()
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct OpenRequest {
    material: String,
}

async fn open(
    State(editor): State<EditorHandle>,
    body: Result<Json<OpenRequest>, JsonRejection>,
) -> ApiResult<Response> {
    let Json(r) = body.map_err(json_error)?;
    editor.catalogue.check(&r.material)?;
    Ok(Json(editor.open(r.material).await?).into_response())
}

#[derive(Deserialize)]
struct UploadQuery {
    name: String,
}

async fn upload(
    State(editor): State<EditorHandle>,
    query: Result<Query<UploadQuery>, QueryRejection>,
    headers: HeaderMap,
    body: Body,
) -> ApiResult<Response> {
    let Query(q) = query.map_err(|e| ApiError(StatusCode::BAD_REQUEST, e.body_text()))?;
    request::check_upload_name(&q.name)?;
    let too_large = || {
        ApiError(
            StatusCode::PAYLOAD_TOO_LARGE,
            format!("upload larger than {} MiB", UPLOAD_LIMIT >> 20),
        )
    };
    // Refused from its announced length at once, before any of it is read.
    let announced = headers.get(header::CONTENT_LENGTH).and_then(|v| v.to_str().ok()?.parse().ok());
    if announced.is_some_and(|n: u64| n > UPLOAD_LIMIT as u64) {
        return Err(too_large());
    }
    let body = axum::body::to_bytes(body, UPLOAD_LIMIT).await.map_err(|_| too_large())?;
    Ok(Json(editor.upload(q.name, body.to_vec()).await?).into_response())
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct OriginalRequest {
    material: String,
    #[serde(default)]
    scene: SceneChoice,
}

fn png_response(png: Vec<u8>) -> Response {
    ([(header::CONTENT_TYPE, "image/png")], png).into_response()
}

async fn original(
    State(editor): State<EditorHandle>,
    body: Result<Json<OriginalRequest>, JsonRejection>,
) -> ApiResult<Response> {
    let Json(r) = body.map_err(json_error)?;
    editor.catalogue.check(&r.material)?;
    let scene = r.scene.config()?;
    Ok(png_response(editor.original(r.material, scene).await?))
}

async fn preview(
    State(editor): State<EditorHandle>,
    body: Result<Json<PreviewRequest>, JsonRejection>,
) -> ApiResult<Response> {
    let Json(r) = body.map_err(json_error)?;
    let edit = r.edit.check(&editor.catalogue)?;
    let preview = editor.preview(edit, r.quality).await?;
    let image = format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&preview.png)
    );
    let mut value = serde_json::to_value(&preview).map_err(|e| {
        ApiError(StatusCode::INTERNAL_SERVER_ERROR, format!("encoding the preview: {e}"))
    })?;
    value["image"] = image.into();
    value["sequence"] = r.sequence.into();
    Ok(Json(value).into_response())
}

#[derive(Deserialize)]
struct DownloadQuery {
    format: String,
    /// The [`EditRequest`] as JSON.
    edit: String,
}

async fn download(
    State(editor): State<EditorHandle>,
    query: Result<Query<DownloadQuery>, QueryRejection>,
) -> ApiResult<Response> {
    let Query(q) = query.map_err(|e| ApiError(StatusCode::BAD_REQUEST, e.body_text()))?;
    let what = match q.format.as_str() {
        "binary" => Download::Binary,
        "bsdf" => Download::Bsdf,
        "latent" => Download::Latent,
        other => {
            return Err(ApiError(
                StatusCode::BAD_REQUEST,
                format!("format {other:?}: expected binary, bsdf or latent"),
            ))
        }
    };
    let edit: EditRequest = serde_json::from_str(&q.edit)
        .map_err(|e| ApiError(StatusCode::BAD_REQUEST, format!("malformed edit: {e}")))?;
    let file = editor.download(edit.check(&editor.catalogue)?, what).await?;
    let kind = match what {
        Download::Binary | Download::Bsdf => "application/octet-stream",
        Download::Latent => "application/json",
    };
    // The file name is made of [A-Za-z0-9_-] by the editor.
    let disposition = format!("attachment; filename=\"{}\"", file.file_name);
    Ok((
        [(header::CONTENT_TYPE, kind.to_string()), (header::CONTENT_DISPOSITION, disposition)],
        file.bytes,
    )
        .into_response())
}
