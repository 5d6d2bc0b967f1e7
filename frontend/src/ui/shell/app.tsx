import { useEffect, useState } from 'preact/hooks';
import { href, useRoute, type Route } from '../../router';
import { useStore } from '../../store';
import { axes, axesLoaded, live, setFocus, statuses, system } from '../../services';
import { Lamp } from '../shared/common';
import { pos } from '../../format';
import { Overview } from './overview';
import { AxisPage } from '../axis/axis-page';
import { AxisConfigPage } from '../config/axis-config';
import { ScopePage } from '../scope/scope';
import { CamListPage, CamPage } from '../cams/cams';
import { GroupsPage } from '../groups/groups';
import type { ConnState } from '../../live/client';
import { ageText } from '../../live/liveness';
import { useLiveness } from '../shared/liveness';
import { UsersPage } from '../auth/users';
import { SystemPage } from '../system/system';
import { ControlBadge, UserBadge } from '../auth/header-auth';
import { auth, may } from '../../auth/session';

function Connection() {
  const c = useStore(live.state);
  const sys = useStore(system);
  const l = useLiveness();
  const [, tick] = useState(0);
  useEffect(() => {
    if (c.kind !== 'closed') return;
    const t = setInterval(() => tick((n) => n + 1), 250);
    return () => clearInterval(t);
  }, [c.kind]);
  if (c.kind === 'open') {
    // Open but silent (no message for a few seconds, though the system topic speaks every second).
    const silent = l.kind === 'stale';
    return (
      <div class={`conn conn-open ${silent ? 'conn-silent' : ''}`} data-conn="open" data-live={l.kind} title={silent ? 'websocket open, but no message for a while' : 'websocket connected'}>
        <span class="conn-dot" />
        <span>{silent ? `silent ${l.ageMs === null ? '' : ageText(l.ageMs)}` : 'online'}</span>
        {sys && (
          <span class="conn-info">
            <span class="conn-cycle-time">cycle {(sys.cycle_time * 1000).toFixed(sys.cycle_time < 0.001 ? 3 : 1)} ms · </span>#{sys.cycle}
          </span>
        )}
      </div>
    );
  }
  if (c.kind === 'connecting') {
    return (
      <div class="conn conn-connecting" data-conn="connecting">
        <span class="conn-dot" />
        connecting…
      </div>
    );
  }
  return (
    <div class="conn conn-closed" data-conn="closed">
      <span class="conn-dot" />
      server gone · retry in {Math.max(0, Math.ceil((c.retryAt - Date.now()) / 1000))} s
      <button type="button" class="btn btn-small" onClick={() => live.retryNow()}>
        retry now
      </button>
    </div>
  );
}

/** Full-width notice while the server cannot be reached: live values are stale. */
function ConnectionNotice({ c }: { c: ConnState }) {
  if (c.kind === 'open') return null;
  if (c.kind === 'connecting' && c.attempt === 0) {
    return <div class="notice notice-info" data-notice="connecting">Connecting to motiond…</div>;
  }
  return (
    <div class="notice notice-error" data-notice="server-gone" role="alert">
      <b>Server gone.</b> motiond does not answer. The values shown are the last received and are <b>not live</b>; commands are
      disabled. Reconnecting automatically{c.attempt > 1 ? ` (attempt ${c.attempt})` : ''}…
    </div>
  );
}

/** The axis list: a column beside the page, on a narrow screen a menu opened from the header. */
function Sidebar({ route, open }: { route: Route; open: boolean }) {
  const list = useStore(axes);
  const st = useStore(statuses);
  const current = route.page === 'axis' ? route.axis : null;
  return (
    <nav class={`sidebar ${open ? 'open' : ''}`} id="sidebar" aria-label="Axes">
      <div class="sidebar-head">Axes</div>
      <ul class="axis-list">
        {list.map((a) => {
          const s = st.get(a.config.name);
          const status = s?.status;
          return (
            <li key={a.id}>
              <a
                href={href({ page: 'axis', axis: a.config.name, tab: route.page === 'axis' ? route.tab : 'online' })}
                class={`axis-item ${current === a.config.name ? 'active' : ''} ${s?.stale ? 'stale' : ''}`}
                data-axis={a.config.name}
              >
                <Lamp state={status?.state ?? a.state} errorId={status?.error_id ?? 0} />
                <span class="axis-item-name">{a.config.name}</span>
                <span class="axis-item-pos">
                  {pos(status?.actual_position)} <small>{a.config.unit}</small>
                </span>
              </a>
            </li>
          );
        })}
      </ul>
      <a class="btn btn-plain sidebar-new" href="#/new-axis">
        + New axis
      </a>
    </nav>
  );
}

export function App() {
  const route = useRoute();
  const conn = useStore(live.state);
  const loaded = useStore(axesLoaded);
  // Users and tokens: for admins, and for anyone while authentication is off (to add the first user).
  const admin = may(useStore(auth), 'admin');
  // Narrow screens (style.css, ≤ 700 px): the axis list is a menu; any navigation closes it.
  const [menuOpen, setMenuOpen] = useState(false);
  useEffect(() => {
    setFocus(route.page === 'axis' && route.tab === 'online' ? route.axis : null);
    setMenuOpen(false);
  }, [route]);
  useEffect(() => {
    if (!menuOpen) return;
    const onKey = (e: KeyboardEvent) => e.key === 'Escape' && setMenuOpen(false);
    window.addEventListener('keydown', onKey);
    return () => window.removeEventListener('keydown', onKey);
  }, [menuOpen]);
  let page;
  switch (route.page) {
    case 'overview':
      page = <Overview />;
      break;
    case 'axis':
      page = <AxisPage key={route.axis} axis={route.axis} tab={route.tab} />;
      break;
    case 'new-axis':
      page = <AxisConfigPage axis={null} />;
      break;
    case 'scope':
      page = <ScopePage />;
      break;
    case 'cams':
      page = <CamListPage />;
      break;
    case 'cam':
      page = <CamPage key={route.table} table={route.table} />;
      break;
    case 'groups':
      page = <GroupsPage group={null} />;
      break;
    case 'group':
      page = <GroupsPage key={route.group} group={route.group} />;
      break;
    case 'users':
      page = <UsersPage />;
      break;
    case 'system':
      page = <SystemPage />;
      break;
    default:
      page = (
        <div class="page">
          <p>
            No page here. <a href="#/">Overview</a>
          </p>
        </div>
      );
  }
  const nav = (r: Route, label: string, active: boolean) => (
    <a href={href(r)} class={`nav-link nav-${r.page} ${active ? 'active' : ''}`}>
      {label}
    </a>
  );
  return (
    <div class={`app app-${conn.kind === 'open' ? 'online' : 'offline'}`}>
      <header class="topbar">
        <button
          type="button"
          class="menu-btn"
          name="menu"
          aria-controls="sidebar"
          aria-expanded={menuOpen}
          title="Axes"
          onClick={() => setMenuOpen(!menuOpen)}
        >
          <span class="menu-icon" aria-hidden="true" />
          Axes
        </button>
        <a class="brand" href="#/">
          motiond
        </a>
        <nav class="nav">
          {nav({ page: 'overview' }, 'Overview', route.page === 'overview')}
          {nav({ page: 'scope' }, 'Scope', route.page === 'scope')}
          {nav({ page: 'cams' }, 'Cams', route.page === 'cams' || route.page === 'cam')}
          {nav({ page: 'groups' }, 'Groups', route.page === 'groups' || route.page === 'group')}
          {nav({ page: 'new-axis' }, 'New axis', route.page === 'new-axis')}
          {nav({ page: 'system' }, 'System', route.page === 'system')}
          {admin && nav({ page: 'users' }, 'Users', route.page === 'users')}
        </nav>
        <div class="topbar-session">
          <ControlBadge />
          <UserBadge />
        </div>
        <div class="topbar-right">
          <a class="nav-link small" href="/docs" target="_blank" rel="noreferrer">
            API
          </a>
          <Connection />
        </div>
      </header>
      <ConnectionNotice c={conn} />
      <div class="body">
        <Sidebar route={route} open={menuOpen} />
        {menuOpen && <div class="menu-backdrop" onClick={() => setMenuOpen(false)} />}
        <main class="main">{loaded || conn.kind === 'open' ? page : <div class="page muted">Waiting for motiond…</div>}</main>
      </div>
    </div>
  );
}
