-- Idempotency-Key of a motion command (the issue "Security and reliability"): stored with the
-- command's submission row, which is committed before the command is acknowledged, so that a
-- retry with the same key after a restart is recognised and not carried out again.
ALTER TABLE audit_log ADD COLUMN idempotency_key TEXT;
CREATE INDEX audit_log_idempotency ON audit_log(idempotency_key) WHERE idempotency_key IS NOT NULL;
