// The status badge's words and colour for a state: honest about the targets. "reached" is green
// only when every target is within the tolerance (and, with observations of the real object,
// the observed object too); a best effort says it is unreachable and why (docs/gui.md).
import { ControllerStatus } from './protocol.js';

const mm = (v) => (1000 * v).toFixed(1);

// {text, kind: 'ok' | 'busy' | 'bad' | '', title}: kind is the badge's CSS class.
export function statusBadge(state) {
  const title = state.status_reason ?? '';
  switch (state.status) {
    case ControllerStatus.Reached: {
      // With observations, "reached" is about the real object, not only the model.
      const real = state.observations > 0 ? state.observed_error : null;
      if (real !== null && real !== undefined && real > state.tolerance)
        return { text: `model reached · real object ${mm(real)} mm off`, kind: 'busy', title };
      return { text: `reached (≤ ${mm(state.tolerance)} mm)`, kind: 'ok', title };
    }
    case ControllerStatus.BestEffort: {
      const why = state.unreachable?.length ? state.unreachable.join(', ') : 'local minimum';
      return { text: `best effort · unreachable: ${why}`, kind: 'bad', title };
    }
    case ControllerStatus.Failed: return { text: 'failed', kind: 'bad', title };
    case ControllerStatus.Optimizing: return { text: state.status, kind: 'busy', title };
    default: return { text: state.status, kind: '', title };
  }
}
