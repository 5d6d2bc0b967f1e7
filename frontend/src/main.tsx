import { render } from 'preact';
import './style.css';
import 'uplot/dist/uPlot.min.css';
import { Root } from './ui/shell/root';
import { live, start, stop } from './services';
import { onUnauthorized } from './api/client';
import { auth, checkSession, sessionEnded } from './auth/session';
import { control } from './auth/control';

// The app runs (websocket, polling, control) only while the page may: authentication off or a
// user logged in. Any 401 (REST, a call over the socket, a socket that cannot open) ends it
// and brings the login page back.
onUnauthorized(() => sessionEnded());
live.onCallError((e) => {
  if (e.problem?.status === 401) sessionEnded();
});
live.onClose(() => {
  // A socket that closed, or could not open: a 401 of its handshake is not visible to a page,
  // so the session is asked (a server that is gone changes nothing here).
  if (auth.get().kind === 'app') void checkSession();
});
auth.subscribe(() => {
  if (auth.get().kind === 'app') {
    start();
    control.start();
  } else {
    control.stop();
    stop();
  }
});
document.addEventListener('visibilitychange', () => control.setHidden(document.visibilityState === 'hidden'));
window.addEventListener('pagehide', () => control.unload());
// Back from the browser's page cache (after a pagehide): read the control again.
window.addEventListener('pageshow', (e) => {
  if (e.persisted && auth.get().kind === 'app') control.start();
});
void checkSession();
render(<Root />, document.getElementById('app')!);
