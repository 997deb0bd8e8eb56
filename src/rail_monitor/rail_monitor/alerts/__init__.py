"""Wayside alerts from the model outputs: raised and cleared with hysteresis (no ROS).

Parameters in :mod:`.config`, the windows and the hysteresis search in :mod:`.windows`, the
standing alerts and their inputs in :mod:`.manager`.

Shared by the ``alert_manager`` node and batch mode; each input stream feeds its own alerts, so
the alerts depend only on each stream's order, not on how streams interleave.

- GRINDING_DUE, one per band (key: the band's centre wavelength): raised when the band's r.m.s.
  reaches its intervention threshold, cleared when it is below ``grinding_clear_fraction`` of it
  (after grinding).
- GRINDING_FORECAST (key ``forecast``): raised when the state's forecast reaches a threshold within
  the corrugation lead time (CorrugationState.grinding_due) while no GRINDING_DUE stands; cleared
  when the forecast is beyond ``forecast_clear_factor`` x the lead time, or when a GRINDING_DUE
  stands (it supersedes the forecast).
- NOISE_LIMIT, one per source model: raised when at least ``noise_raise_count`` of the last
  ``noise_window_passes`` passes exceed ``noise_limit_dba`` on ``noise_metric``; cleared when at
  most ``noise_clear_count`` of them exceed the limit minus ``noise_hysteresis_db``.
- SQUEAL (key ``site``): the same on the share of the last ``squeal_window_passes`` passes whose
  squeal risk is at least ``squeal_min_risk``: raised at ``squeal_raise_share``, cleared at or below
  ``squeal_clear_share``.
- INPUT_REJECTED (key ``train_pass``): the same on the rejected share of the last
  ``rejected_window_passes`` TrainPass messages.
"""

