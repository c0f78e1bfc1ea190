"""The editor's level of detail: a big mesh is drawn as its proxy while it moves.

For a mesh of more than :data:`~rigedit.render.proxy.PROXY_MIN_FACES` triangles, the view
builds a :class:`~rigedit.render.proxy.SkinProxy` in a worker thread when the rig is opened
(several seconds for 500k triangles; the full mesh is drawn meanwhile), shows it from the
first pose change of a drag, a playback or a panel edit, and the full mesh again once no pose
has changed for :attr:`ProxyView.settle_ms` while no joint is held (after a release or a
pause). A label in the status bar says which is shown. Not used in the weight paint view,
which colours and picks the full mesh.
"""
from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

from PyQt5 import QtCore, QtWidgets

from ..editor import events as ev
from ..render.proxy import PROXY_MIN_FACES, build_proxy

__all__ = ["ProxyView"]


class ProxyView:
    """Switches the window's scene between its proxy and the full mesh.

    Parameters
    ----------
    scene_source : callable() -> RigScene
        The current scene (the window rebuilds it when a rig is opened).
    document : Document
    status_bar : QStatusBar
        Gets a permanent label naming what is drawn.
    request_render : callable()
        Asks the view to repaint once.
    weights_view : callable() -> bool
        Whether the weight paint view is on (the proxy is then not used).
    min_faces : int
        Meshes with more triangles get a proxy.
    """

    #: Milliseconds without a pose change (and no joint held) before the full mesh returns.
    settle_ms = 250

    def __init__(self, scene_source, document, status_bar, request_render, weights_view,
                 min_faces=PROXY_MIN_FACES):
        self.scene_source = scene_source
        self.document = document
        self.request_render = request_render
        self.weights_view = weights_view
        self.min_faces = min_faces
        self.label = QtWidgets.QLabel()
        self.label.setVisible(False)
        status_bar.addPermanentWidget(self.label)
        self.timer = QtCore.QTimer(status_bar)   # dies with the window
        self.timer.setSingleShot(True)
        self.timer.setInterval(self.settle_ms)
        self.timer.timeout.connect(self._settle)
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="rigedit-proxy")
        self._building = None   # (future, binding it is built for)
        self._poll = QtCore.QTimer(status_bar)
        self._poll.setInterval(100)
        self._poll.timeout.connect(self._collect)
        document.listen(self._on_event)
        self.attach()

    @property
    def building(self):
        """Whether a proxy is being built in the worker thread."""
        return self._building is not None

    def attach(self):
        """Start building the proxy of the current rig's mesh when it is big enough."""
        rig = self.document.rig
        self._building = None
        if self.scene_source().has_mesh and len(rig.faces) > self.min_faces:
            self._building = (self._pool.submit(build_proxy, rig.binding, rig.faces),
                              rig.binding)
            self._poll.start()
        self._show_label()

    def _collect(self):
        """On the UI thread: attach the finished proxy, unless the rig changed meanwhile."""
        if self._building is None:
            self._poll.stop()
            return
        future, binding = self._building
        if not future.done():
            return
        self._building = None
        self._poll.stop()
        proxy = future.result()   # an error here is a bug: the window's hook reports it
        if binding is self.document.rig.binding:
            self.scene_source().attach_proxy(proxy)
        elif self.document.rig.binding.num_vertices == binding.num_vertices:
            self.scene_source().attach_proxy(proxy.rebind(self.document.rig.binding))
        self._show_label()

    def _on_event(self, event):
        scene = self.scene_source()
        if isinstance(event, ev.RigReplaced):
            self.attach()
        elif scene.proxy is None:
            return
        elif isinstance(event, (ev.RestChanged, ev.WeightsChanged)):   # new weights
            scene.attach_proxy(scene.proxy.rebind(self.document.rig.binding))
            self._show_label()
        elif isinstance(event, ev.PoseChanged):
            if self.weights_view():
                self._settle()
                return
            if scene.show_proxy(True):
                self._show_label()
            self.timer.start()

    def _settle(self):
        """Back to the full mesh, unless a joint is still held."""
        if self.document.dragging and not self.weights_view():
            self.timer.start()
            return
        if self.scene_source().show_proxy(False):
            self._show_label()
            self.request_render()

    def _show_label(self):
        scene = self.scene_source()
        proxy = scene.proxy
        self.label.setVisible(proxy is not None or self.building)
        if proxy is None:
            if self.building:
                self.label.setText(f"  Full mesh: {len(self.document.rig.faces):,} triangles "
                                   f"(preparing a proxy)  ")
            return
        if scene.proxy_shown:
            self.label.setText(f"  Proxy: {proxy.num_faces:,} of {proxy.full_faces:,} "
                               f"triangles while moving  ")
        else:
            self.label.setText(f"  Full mesh: {proxy.full_faces:,} triangles  ")

    def stop(self):
        self.timer.stop()
        self._poll.stop()
        self._building = None
        self._pool.shutdown(wait=False, cancel_futures=True)
