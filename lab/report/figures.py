"""The report's figures, drawn with matplotlib (Agg backend: no display needed) from analysis results."""
import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402  (the backend must be chosen first)

LED_COLOURS = {'GREEN': '#2ca02c', 'RED': '#d62728'}


def _led_band(ax, changes, end):
    """The LED colour over time as a coloured band, GREEN from the start."""
    edges = [(0.0, 'GREEN')] + list(changes)
    for (start, colour), (stop, _) in zip(edges, edges[1:] + [(end, None)]):
        ax.axvspan(start, stop, color=LED_COLOURS[colour], alpha=0.85, lw=0)
    ax.set_yticks([])
    ax.set_ylabel('LED', rotation=0, ha='right', va='center')


def run_figure(path, facts, title, quantity, unit, threshold, delay, service, invert=False,
               xlabel='time since roslaunch [s]'):
    """True value (when recorded), published estimate, threshold, LED state and service-call instants
    of one run."""
    end = max(t for t, _ in facts['published'])
    fig, (ax, led) = plt.subplots(2, 1, sharex=True, figsize=(11, 4.0),
                                  gridspec_kw={'height_ratios': [6, 1], 'hspace': 0.08})
    for start, stop, _ in facts['episodes']:
        ax.axvspan(start, end if stop is None else stop, color='#ffcc80', alpha=0.35, lw=0)
    if facts['truth']:
        ax.plot(*zip(*facts['truth']), color='black', lw=1.2, label='true %s (simulator ground truth)' % quantity)
    ax.plot(*zip(*facts['published']), color='#1f77b4', lw=1.0, alpha=0.9,
            label='/%s published by the exam node (10 Hz)' % quantity)
    ax.axhline(threshold, color='#d62728', ls='--', lw=1.0, label='threshold %g %s' % (threshold, unit))
    for t, colour in facts['changes']:
        status = 'WARNING' if colour == 'RED' else 'NORMAL'
        for axis in (ax, led):
            axis.axvline(t, color='#7f007f', ls=':', lw=1.2)
        ax.annotate('%s call\n%.1f s' % (status, t), xy=(t, threshold), xytext=(4, 10 if not invert else -24),
                    textcoords='offset points', fontsize=8, color='#7f007f')
    ax.plot([], [], color='#ffcc80', lw=6, alpha=0.6, label='estimate above the threshold (reading by reading)')
    ax.plot([], [], color='#7f007f', ls=':', label='%s service call (LED change)' % service)
    if invert:
        ax.invert_yaxis()
    ax.set_ylabel('%s [%s]' % (quantity, unit))
    ax.set_title('%s: threshold %g %s, delay %g s' % (title, threshold, unit, delay), fontsize=10)
    ax.legend(fontsize=7.5, loc='upper left', bbox_to_anchor=(1.01, 1.0), framealpha=0.9)
    ax.grid(alpha=0.3)
    _led_band(led, facts['changes'], end)
    led.set_xlabel(xlabel)
    led.set_xlim(0.0, end)
    fig.savefig(path, dpi=110, bbox_inches='tight')
    plt.close(fig)


def model_error_figure(path, curve, fixed, measured, threshold):
    """Error of equation (1) against the ISA truth, the lapse-rate fix, and errors measured in flight.

    :param curve: [(altitude, error)] of the isothermal formula. :param fixed: the same for the fix.
    :param measured: [(true altitude, error)] from the recorded flight while the altitude held still.
    """
    fig, ax = plt.subplots(figsize=(8, 4.2))
    ax.plot(*zip(*curve), color='#1f77b4', lw=1.5,
            label='equation (1), local T, isothermal column (the exam formula)')
    ax.plot(*zip(*fixed), color='#2ca02c', lw=1.5, ls='--',
            label='ISA lapse-rate formula, local T (the fix)')
    if measured:
        ax.plot(*zip(*measured), ls='none', marker='.', ms=4, color='#ff7f0e', alpha=0.7,
                label='recorded flight, /altitude - true altitude (noisy sensors)')
    at = [e for h, e in curve if h == threshold]
    if at:
        ax.annotate('%.1f m at %g m' % (at[0], threshold), xy=(threshold, at[0]), xytext=(20, -25),
                    textcoords='offset points', arrowprops={'arrowstyle': '->'}, fontsize=9)
    ax.axvline(threshold, color='#d62728', ls=':', lw=1.0)
    ax.set_xlabel('true altitude (ISA troposphere) [m]')
    ax.set_ylabel('estimate - truth [m]')
    ax.set_title('Altitude error of the isothermal model against the ISA atmosphere', fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc='lower left')
    fig.savefig(path, dpi=110, bbox_inches='tight')
    plt.close(fig)
