// Hooks shared by the Coupling and Functions tabs.
import { useEffect, useState } from 'preact/hooks';
import { useStore } from '../store';
import { commandLog, type LogEntry } from '../services';
import { api } from '../api/client';
import type { CommandResource } from '../api/types';
import type { Form } from './bodies';

/** A form's text inputs as one record. */
export function useForm(init: Form): [Form, (k: string, v: string) => void, (f: Form) => void] {
  const [f, setF] = useState<Form>(init);
  return [f, (k, v) => setF((o) => ({ ...o, [k]: v })), setF];
}

/**
 * The running (not final) command `name` of an axis in the command log — an Enable-type block
 * this page or another client started — or null.
 */
export function useRunning(axis: string, name: string): LogEntry | null {
  const log = useStore(commandLog);
  return log.find((e) => e.axis === axis && e.command === name && e.id !== null && !e.final) ?? null;
}

/** The command log's entry of a command (follows its events), or null. */
export function useLogEntry(id: number | null | undefined): LogEntry | null {
  const log = useStore(commandLog);
  return id ? (log.find((e) => e.id === id) ?? null) : null;
}

/**
 * The command resource of `id`, read again whenever the command log shows a new event of it
 * (its outputs: in_gear, in_sync … and its error_code) or `key` changes; a failed read is
 * tried again a few times.
 */
export function useCommand(id: number | null | undefined, key = ''): CommandResource | null {
  const entry = useLogEntry(id);
  const [r, setR] = useState<CommandResource | null>(null);
  const tick = entry ? `${entry.state}/${entry.cycle}/${entry.final}` : '';
  useEffect(() => {
    if (!id) {
      setR(null);
      return;
    }
    let live = true;
    let timer: ReturnType<typeof setTimeout> | null = null;
    const read = (tries: number) =>
      api.GET('/api/v1/commands/{id}', { params: { path: { id } } }).then(
        (c) => live && setR(c),
        () => {
          if (live && tries > 0) timer = setTimeout(() => void read(tries - 1), 1000);
        },
      );
    void read(5);
    return () => {
      live = false;
      if (timer) clearTimeout(timer);
    };
  }, [id, tick, key]);
  return r && r.id === id ? r : null;
}
