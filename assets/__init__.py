"""The bundled characters, installed as the data package ``rigedit.assets`` (see setup.py).

Each sub-folder (``quadruped``, ``humanoid``) is a rig folder; ``rigedit.ASSETS_DIR`` is this
folder. This file holds no code: it makes the folder a regular package so that
``importlib.resources`` finds it in a normal install and in an editable one alike.
"""
