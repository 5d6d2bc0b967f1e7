//! TLS (rustls on ring): the certificate given with `--tls-cert`/`--tls-key`, or a self-signed
//! one made on first start and kept beside the database, so that its fingerprint — which the
//! engineer pins in the browser or the MES — stays the same across restarts.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use rustls_pki_types::pem::PemObject;
use rustls_pki_types::{CertificateDer, PrivateKeyDer};
use tokio_rustls::TlsAcceptor;
use tokio_rustls::rustls;

use crate::cli::ServeArgs;

/// SHA-256 of a certificate, as browsers show it (`AB:CD:…`).
pub fn fingerprint(der: &[u8]) -> String {
    let d = ring::digest::digest(&ring::digest::SHA256, der);
    d.as_ref()
        .iter()
        .map(|b| format!("{b:02X}"))
        .collect::<Vec<_>>()
        .join(":")
}

/// Where the self-signed certificate and key of a database live.
fn self_signed_paths(db: &str) -> Result<(PathBuf, PathBuf), String> {
    if db == ":memory:" {
        return Err(
            "TLS without --tls-cert needs a database file (the self-signed certificate is kept beside it); \
             give --tls-cert and --tls-key with --db :memory:"
                .into(),
        );
    }
    let dir = Path::new(db)
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let stem = Path::new(db)
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "motiond.db".into());
    Ok((
        dir.join(format!("{stem}.tls-cert.pem")),
        dir.join(format!("{stem}.tls-key.pem")),
    ))
}

/// The names a self-signed certificate must carry: loopback, the listening address, every
/// `--public-name` (once each).
fn served_names(args: &ServeArgs) -> Vec<String> {
    let mut names = vec![
        "localhost".to_string(),
        "127.0.0.1".to_string(),
        "::1".to_string(),
    ];
    if !args.listen.ip().is_unspecified() {
        names.push(args.listen.ip().to_string());
    }
    names.extend(
        args.public_names
            .iter()
            .map(|n| n.trim_matches(['[', ']']).to_string()),
    );
    // Not only adjacent duplicates: the order of the rest is kept.
    let mut seen = std::collections::HashSet::new();
    names.retain(|n| seen.insert(n.clone()));
    names
}

/// The served names a kept certificate is not valid for (all of them when it cannot be read).
fn names_missing(cert: &Path, names: &[String]) -> Vec<String> {
    let Some(der) = CertificateDer::pem_file_iter(cert)
        .ok()
        .and_then(|mut it| it.next())
        .and_then(Result::ok)
    else {
        return names.to_vec();
    };
    let Ok(ee) = webpki::EndEntityCert::try_from(&der) else {
        return names.to_vec();
    };
    names
        .iter()
        .filter(|n| {
            rustls_pki_types::ServerName::try_from(n.as_str())
                .map_or(true, |sn| ee.verify_is_valid_for_subject_name(&sn).is_err())
        })
        .cloned()
        .collect()
}

/// Makes a self-signed certificate for the names motiond serves.
fn make_self_signed(args: &ServeArgs, cert: &Path, key: &Path) -> Result<(), String> {
    let names = served_names(args);
    let ck = rcgen::generate_simple_self_signed(names.clone())
        .map_err(|e| format!("cannot make a self-signed certificate: {e}"))?;
    // The key first, readable by the owner only.
    write_private(key, ck.key_pair.serialize_pem().as_bytes())?;
    std::fs::write(cert, ck.cert.pem())
        .map_err(|e| format!("cannot write {}: {e}", cert.display()))?;
    tracing::info!(
        "made a self-signed TLS certificate for {} ({})",
        names.join(", "),
        cert.display()
    );
    Ok(())
}

fn write_private(path: &Path, bytes: &[u8]) -> Result<(), String> {
    use std::io::Write;
    use std::os::unix::fs::OpenOptionsExt;
    let mut f = std::fs::OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(true)
        .mode(0o600)
        .open(path)
        .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    f.write_all(bytes)
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// The TLS acceptor for `serve`.
pub fn acceptor(args: &ServeArgs) -> Result<TlsAcceptor, String> {
    let (cert_path, key_path) = match (&args.tls_cert, &args.tls_key) {
        (Some(c), Some(k)) => (c.clone(), k.clone()),
        _ => {
            let (c, k) = self_signed_paths(&args.db)?;
            if !c.exists() || !k.exists() {
                make_self_signed(args, &c, &k)?;
            } else {
                // `--listen` or `--public-name` changed since it was made: a certificate that
                // does not name what motiond now serves is renewed (its fingerprint changes;
                // a name dropped since keeps the certificate, and its fingerprint, as it is).
                let missing = names_missing(&c, &served_names(args));
                if !missing.is_empty() {
                    tracing::warn!(
                        "the self-signed TLS certificate {} does not name {}: making a new one \
                         (its fingerprint changes: pin the new one in browsers and clients)",
                        c.display(),
                        missing.join(", ")
                    );
                    make_self_signed(args, &c, &k)?;
                }
            }
            (c, k)
        }
    };
    let certs: Vec<CertificateDer<'static>> = CertificateDer::pem_file_iter(&cert_path)
        .map_err(|e| format!("cannot read {}: {e}", cert_path.display()))?
        .collect::<Result<_, _>>()
        .map_err(|e| format!("{}: not a PEM certificate chain: {e}", cert_path.display()))?;
    let Some(first) = certs.first() else {
        return Err(format!("{}: no certificate in it", cert_path.display()));
    };
    tracing::info!(
        "TLS certificate {} SHA-256 fingerprint {}",
        cert_path.display(),
        fingerprint(first)
    );
    let key = PrivateKeyDer::from_pem_file(&key_path)
        .map_err(|e| format!("cannot read the private key {}: {e}", key_path.display()))?;
    let config = rustls::ServerConfig::builder_with_provider(Arc::new(
        rustls::crypto::ring::default_provider(),
    ))
    .with_safe_default_protocol_versions()
    .map_err(|e| e.to_string())?
    .with_no_client_auth()
    .with_single_cert(certs, key)
    .map_err(|e| format!("the TLS certificate and key do not go together: {e}"))?;
    Ok(TlsAcceptor::from(Arc::new(config)))
}
