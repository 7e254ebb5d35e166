"""The plugin's widget: a labels movie in the viewer, or two single-frame labels layers (an
earlier and a later time point), mapped by :func:`morphomap.map_series` in a thread worker, its
results added as layers and its quality shown in a table.

Every failure (no labels layer, an empty object, a pair that cannot be mapped, a folder that
cannot be written) is shown as a napari error notification; nothing raises out of the viewer.
"""

from __future__ import annotations

import warnings

import numpy as np
from napari.layers import Labels
from napari.qt.threading import create_worker
from napari.utils.notifications import show_error, show_info, show_warning
from qtpy.QtWidgets import (QComboBox, QDoubleSpinBox, QFileDialog, QFormLayout, QLabel, QPushButton, QSpinBox,
                            QTableWidget, QTableWidgetItem, QVBoxLayout, QWidget)

from .compute import CHOICES, DRIFT, Frame, Options, check_labels, map_labels, methods, pair_movie, spatial_dim
from .layers import series_layers

#: The quality table's columns: a title and how to read it off a row of ``series.quality``.
COLUMNS = (("step", lambda q: str(q.step)), ("QM1", lambda q: f"{q.qm1:.3f}"), ("QM2", lambda q: f"{q.qm2:.3f}"),
           ("QM", lambda q: f"{q.qm:.3f}"), ("crossings", lambda q: str(q.defects)),
           ("misses", lambda q: str(q.misses)))
#: The smoothing box's lowest value stands for None (the mask readers' own default width).
AUTO_SMOOTH = -0.1
#: The later layer's choice that maps the first layer alone, as a movie.
NONE = "none"
#: What the two layer boxes say when the mouse rests on them.
LABELS_TIP = ("The labels to map: a movie with time first (2D + t or 3D + t), mapped as a series; or, "
              "with a later layer chosen below, the earlier of two time points.")
LATER_TIP = ("Two-layer mode: the later time point, mapped from the layer above (the earlier). Each layer is "
             "one frame without a time axis (2D: rows, columns; 3D: planes, rows, columns; a layer of three "
             "axes is a 3D stack unless morphomap's reader opened it as a 2D movie); a movie is refused, not "
             "cut to its current time step. Both need the same shape, scale and translate. The results have "
             "a time axis of 2: 0 the earlier layer, 1 the later. 'none': map the layer above as a movie.")


def _map_in_steps(data, spacing, options, dt, unit, scale, translate):
    """The worker: map, then make the layers' data; yields once per stage for the progress bar.
    Warnings (an object touching the border, one in several parts) are returned to be shown."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        series = map_labels(data, spacing, options, dt=dt, unit=unit)
        yield "mapped"
        layers = series_layers(series, spacing, scale, translate)
        yield "layers"
    return series, layers, [str(w.message) for w in caught]


def _frame(layer) -> Frame:
    """A napari Labels layer as :func:`morphomap.napari.compute.pair_movie` takes it."""
    metadata = layer.metadata or {}
    return Frame(layer.name, layer.data, tuple(float(v) for v in layer.scale),
                 tuple(float(v) for v in layer.translate), metadata.get("axes"), metadata.get("unit"))


class SeriesWidget(QWidget):
    """Map a Labels movie (2D + t or 3D + t) through time, or one Labels layer onto another (two
    single frames, 2D or 3D: the earlier and the later time point), and show the result.

    Two-layer mode (a layer chosen in ``later``) stacks the two frames into a movie of 2 frames
    and maps it as a series, so that the results are the same layers with a time axis of 2. Each
    layer must be one frame: a movie is refused with a notification, never cut to its current
    time step. The two must have the same shape, scale and translate.

    Parameters
    ----------
    napari_viewer : napari.viewer.Viewer
        The viewer whose Labels layers are offered and which receives the results.

    Attributes
    ----------
    labels, later : QComboBox
        The Labels layer to map (a movie, or the earlier frame), and the later frame (``"none"``:
        map ``labels`` as a movie).
    series : morphomap.series.Series or None
        The last result.
    busy : bool
        Whether a worker (mapping or writing) is running; tests wait on it.
    """

    def __init__(self, napari_viewer):
        super().__init__()
        self.viewer = napari_viewer
        self.series, self.busy, self._source, self._frames_note = None, False, None, ""
        self.labels = QComboBox()
        self.labels.setToolTip(LABELS_TIP)
        self.later = QComboBox()
        self.later.setToolTip(LATER_TIP)
        self.objects = QComboBox()
        self.objects.addItems(CHOICES)
        self.label = QSpinBox()
        self.label.setRange(0, 2**31 - 1)
        self.label.setSpecialValueText("none")
        self.smooth = QDoubleSpinBox()
        self.smooth.setRange(AUTO_SMOOTH, 1e4)
        self.smooth.setSingleStep(0.1)
        self.smooth.setDecimals(2)
        self.smooth.setSpecialValueText("auto")
        self.smooth.setValue(AUTO_SMOOTH)
        self.method = QComboBox()
        self.drift = QComboBox()
        self.drift.addItems(DRIFT)
        self.run_button = QPushButton("Map series")
        self.write_button = QPushButton("Write series folder…")
        self.write_button.setEnabled(False)
        self.status = QLabel("")
        self.status.setWordWrap(True)
        self.table = QTableWidget(0, len(COLUMNS))
        self.table.setHorizontalHeaderLabels([title for title, _ in COLUMNS])
        form = QFormLayout()
        for title, box in (("labels", self.labels), ("later labels", self.later), ("object", self.objects),
                           ("label", self.label), ("smoothing", self.smooth), ("method", self.method),
                           ("drift", self.drift)):
            form.addRow(title, box)
        layout = QVBoxLayout(self)
        layout.addLayout(form)
        for item in (self.run_button, self.status, self.table, self.write_button):
            layout.addWidget(item)
        self.run_button.clicked.connect(self.run)
        self.write_button.clicked.connect(lambda: self.write())
        self.labels.currentIndexChanged.connect(self._offer_methods)
        self.later.currentIndexChanged.connect(self._offer_methods)
        for event in (napari_viewer.layers.events.inserted, napari_viewer.layers.events.removed,
                      napari_viewer.layers.events.moved):
            event.connect(self._offer_layers)
        self._offer_layers()

    # -- what the widget offers --------------------------------------------------------------
    def _labels_layers(self) -> list:
        return [layer for layer in self.viewer.layers if isinstance(layer, Labels)]

    def _offer_layers(self, *_):
        names = [layer.name for layer in self._labels_layers()]
        for box, offered in ((self.labels, names), (self.later, [NONE] + names)):
            current = box.currentText()
            box.blockSignals(True)
            box.clear()
            box.addItems(offered)
            if current in offered:
                box.setCurrentText(current)
            box.blockSignals(False)
        self._offer_methods()

    def _offer_methods(self, *_):
        layer = self.layer()
        single = self.later_layer() is not None
        dim = 2 if layer is None else spatial_dim(layer.data.ndim, (layer.metadata or {}).get("axes"),
                                                   single_frame=single)
        self.run_button.setText("Map pair" if single else "Map series")
        current = self.method.currentText() or "auto"
        self.method.clear()
        self.method.addItems(methods(dim))
        self.method.setCurrentText(current if current in methods(dim) else "auto")
        self.table.setHorizontalHeaderItem(4, QTableWidgetItem("crossings" if dim == 2 else "folds"))

    def layer(self):
        """The chosen Labels layer, or None."""
        name = self.labels.currentText()
        return next((layer for layer in self._labels_layers() if layer.name == name), None)

    def later_layer(self):
        """The Labels layer chosen as the later time point (two-layer mode), or None."""
        name = self.later.currentText()
        if name in ("", NONE):
            return None
        return next((layer for layer in self._labels_layers() if layer.name == name), None)

    def options(self) -> Options:
        """The settings as :func:`morphomap.napari.compute.map_labels` takes them."""
        smooth = self.smooth.value()
        return Options(objects=self.objects.currentText(), label=self.label.value() or None,
                       smooth=None if smooth <= AUTO_SMOOTH / 2 else float(smooth),
                       method=self.method.currentText(), drift=self.drift.currentText())

    # -- mapping -------------------------------------------------------------------------------
    def run(self):
        """Map the chosen layer in a thread worker (napari's progress bar counts its stages) and
        add the results as layers. Returns the worker, or None where the input is refused (with
        an error notification)."""
        if self.busy:
            show_info("morphomap: a series is already being mapped")
            return None
        try:
            source, data, spacing, dt, unit, scale, translate = self._input()
            options = self.options()
        except (ValueError, TypeError) as error:
            show_error(f"morphomap: {error}")
            return None
        self.busy, self._source = True, source
        self.status.setText(f"mapping {source}…")
        return create_worker(_map_in_steps, np.asarray(data), spacing, options, dt, unit, scale, translate,
                             _progress={"total": 2, "desc": "morphomap: mapping"},
                             _connect={"returned": self._show, "errored": self._map_failed, "finished": self._idle})

    def _input(self) -> tuple:
        """``(name, data, spacing, dt, unit, scale, translate)`` of the chosen layer (a movie), or
        of the two chosen layers stacked into a movie of 2 frames; raises where they cannot be
        mapped."""
        layer, later = self.layer(), self.later_layer()
        if layer is None:
            raise ValueError("labels: no Labels layer to map; open or add a labels movie (time first)")
        self._frames_note = ""
        if later is None:
            data, spacing = check_labels(layer.data, tuple(float(v) for v in layer.scale[1:]))
            metadata = layer.metadata or {}
            return (layer.name, data, spacing, metadata.get("frame_interval"), metadata.get("unit"),
                    tuple(layer.scale), tuple(layer.translate))
        data, spacing, unit = pair_movie(_frame(layer), _frame(later))
        self._frames_note = f" (frame 0 is the layer {layer.name!r}, frame 1 the layer {later.name!r})"
        return (f"{layer.name} to {later.name}", data, spacing, None, unit, (1.0, *layer.scale),
                (0.0, *layer.translate))

    def _show(self, result):
        series, layers, said = result
        try:
            for message in dict.fromkeys(said):
                show_warning(f"morphomap: {message}{self._frames_note}")
            for data, options, kind in layers:
                name = f"{self._source} {options['name']}"
                if name in self.viewer.layers:
                    self.viewer.layers.remove(name)
                getattr(self.viewer, f"add_{kind}")(data, **dict(options, name=name))
        except Exception as error:  # a layer napari refuses must not take the viewer down
            show_error(f"morphomap: the results could not be shown: {error}")
            return
        self.series = series
        self._fill_table(series)
        self.write_button.setEnabled(True)
        lost = int(np.isnan(series.trajectories[-1]).any(axis=1).sum())
        self.status.setText(f"{len(series.frames)} frames, {series.trajectories.shape[1]} points followed, "
                            f"{lost} lost")

    def _fill_table(self, series):
        self.table.setRowCount(len(series.quality))
        for row, q in enumerate(series.quality):
            for column, (_, read) in enumerate(COLUMNS):
                self.table.setItem(row, column, QTableWidgetItem(read(q)))
        self.table.resizeColumnsToContents()

    def _map_failed(self, error):
        self._failed(error, self._frames_note)

    def _failed(self, error, note=""):
        self.status.setText("failed")
        show_error(f"morphomap: {error}{note}")

    def _idle(self, *_):
        self.busy = False

    # -- writing -------------------------------------------------------------------------------
    def write(self, folder=None):
        """Write the last series into ``folder`` (:meth:`morphomap.series.Series.write`; asked for
        with a dialog when None) in a thread worker. Returns the worker, or None."""
        if self.series is None:
            show_error("morphomap: nothing to write yet; map a series first")
            return None
        if folder is None:
            folder = QFileDialog.getExistingDirectory(self, "Write the series into")
            if not folder:
                return None
        self.busy = True
        self.status.setText(f"writing {folder}…")
        return create_worker(self.series.write, folder, _progress={"total": 0, "desc": "morphomap: writing"},
                             _connect={"returned": lambda paths: self._written(folder, paths),
                                       "errored": self._failed, "finished": self._idle})

    def _written(self, folder, paths):
        self.status.setText(f"wrote {len(paths)} files into {folder}")
        show_info(f"morphomap: wrote {len(paths)} files into {folder}")
