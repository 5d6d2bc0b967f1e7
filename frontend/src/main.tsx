import { render } from 'preact';
import './style.css';
import 'uplot/dist/uPlot.min.css';
import { App } from './ui/app';
import { start } from './services';

start();
render(<App />, document.getElementById('app')!);
