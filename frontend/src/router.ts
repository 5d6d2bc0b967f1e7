import { useEffect, useState } from 'preact/hooks';

/** The tabs of an axis page. */
export type AxisTab = 'online' | 'coupling' | 'functions' | 'parameters' | 'config';
const AXIS_TABS: readonly string[] = ['online', 'coupling', 'functions', 'parameters', 'config'];

export type Route =
  | { page: 'overview' }
  | { page: 'axis'; axis: string; tab: AxisTab }
  | { page: 'new-axis' }
  | { page: 'scope' }
  | { page: 'cams' }
  | { page: 'cam'; table: string }
  | { page: 'groups' }
  | { page: 'group'; group: string }
  | { page: 'users' }
  | { page: 'system' }
  | { page: 'not-found'; path: string };

export function parseRoute(hash: string): Route {
  const path = hash.replace(/^#/, '') || '/';
  const parts = path.split('/').filter(Boolean).map(decodeURIComponent);
  if (parts.length === 0) return { page: 'overview' };
  if (parts[0] === 'scope' && parts.length === 1) return { page: 'scope' };
  if (parts[0] === 'cams' && parts.length === 1) return { page: 'cams' };
  if (parts[0] === 'cams' && parts.length === 2) return { page: 'cam', table: parts[1] };
  if (parts[0] === 'groups' && parts.length === 1) return { page: 'groups' };
  if (parts[0] === 'groups' && parts.length === 2) return { page: 'group', group: parts[1] };
  if (parts[0] === 'new-axis' && parts.length === 1) return { page: 'new-axis' };
  if (parts[0] === 'users' && parts.length === 1) return { page: 'users' };
  if (parts[0] === 'system' && parts.length === 1) return { page: 'system' };
  if (parts[0] === 'axes' && parts.length >= 2 && parts.length <= 3) {
    const tab = parts[2] ?? 'online';
    if (AXIS_TABS.includes(tab)) return { page: 'axis', axis: parts[1], tab: tab as AxisTab };
  }
  return { page: 'not-found', path };
}

export function href(r: Route): string {
  switch (r.page) {
    case 'overview':
      return '#/';
    case 'scope':
      return '#/scope';
    case 'cams':
      return '#/cams';
    case 'cam':
      return `#/cams/${encodeURIComponent(r.table)}`;
    case 'groups':
      return '#/groups';
    case 'group':
      return `#/groups/${encodeURIComponent(r.group)}`;
    case 'new-axis':
      return '#/new-axis';
    case 'users':
      return '#/users';
    case 'system':
      return '#/system';
    case 'axis':
      return `#/axes/${encodeURIComponent(r.axis)}${r.tab === 'online' ? '' : '/' + r.tab}`;
    default:
      return '#/';
  }
}

export function navigate(r: Route): void {
  location.hash = href(r);
}

export function useRoute(): Route {
  const [route, setRoute] = useState(() => parseRoute(location.hash));
  useEffect(() => {
    const on = () => setRoute(parseRoute(location.hash));
    window.addEventListener('hashchange', on);
    return () => window.removeEventListener('hashchange', on);
  }, []);
  return route;
}
