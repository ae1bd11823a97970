"""MJCF and URDF files in the encoding their XML declaration names (XML 1.0, section 4.3.3)."""

from __future__ import annotations

import pytest

from robomech import multibody as mb

NAME = "b\xe9ta"  # "béta": not ASCII, one byte in latin-1, two in UTF-8
MJCF = (
    '<?xml version="1.0" encoding="{enc}"?>\n<mujoco model="m"><worldbody><body name="' + NAME + '">'
    '<joint name="j' + NAME + '" type="hinge"/><geom size=".1" mass="1"/></body></worldbody>'
    '<actuator><motor joint="j' + NAME + '"/></actuator></mujoco>'
)
URDF = (
    '<?xml version="1.0" encoding="{enc}"?>\n<robot name="r"><link name="base"/><link name="' + NAME + '">'
    '<inertial><mass value="1"/><inertia ixx=".01" iyy=".01" izz=".01" ixy="0" ixz="0" iyz="0"/></inertial>'
    '</link><joint name="j" type="revolute"><parent link="base"/><child link="' + NAME + '"/>'
    '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>'
)


@pytest.mark.parametrize("enc", ["ISO-8859-1", "latin-1", "cp1252", "UTF-8"])
def test_an_mjcf_file_is_read_in_its_declared_encoding(tmp_path, enc):
    path = tmp_path / "m.xml"
    path.write_bytes(MJCF.format(enc=enc).encode(enc))
    mech = mb.from_mjcf(path)
    assert [b.name for b in mech.bodies] == [NAME]
    assert mech.actuated == ("j" + NAME,)


def test_control_latin1_bytes_declared_utf8_are_refused_naming_the_byte(tmp_path):
    path = tmp_path / "m.xml"
    path.write_bytes(MJCF.format(enc="UTF-8").encode("latin-1"))  # the declaration lies
    with pytest.raises(ValueError, match="Expected path_or_xml to be UTF-8"):
        mb.from_mjcf(path)


def test_an_unknown_declared_encoding_is_refused_naming_it(tmp_path):
    path = tmp_path / "m.xml"
    path.write_bytes(MJCF.format(enc="no-such-codec").encode("ascii", "replace"))
    with pytest.raises(ValueError, match="no-such-codec"):
        mb.from_mjcf(path)


def test_bytes_outside_the_declared_encoding_are_refused(tmp_path):
    path = tmp_path / "m.xml"
    path.write_bytes(MJCF.format(enc="ascii").encode("latin-1"))
    with pytest.raises(ValueError, match=r"Expected path_or_xml to be (ascii|UTF-8)"):
        mb.from_mjcf(path)


@pytest.mark.parametrize("enc", ["ISO-8859-1", "UTF-8"])
def test_a_urdf_file_is_read_in_its_declared_encoding(tmp_path, enc):
    path = tmp_path / "r.urdf"
    path.write_bytes(URDF.format(enc=enc).encode(enc))
    assert [b.name for b in mb.from_urdf(path).bodies] == ["base", NAME]


def test_a_urdf_with_an_unknown_declared_encoding_is_refused_naming_it(tmp_path):
    path = tmp_path / "r.urdf"
    path.write_bytes(URDF.format(enc="no-such-codec").encode("ascii", "replace"))
    with pytest.raises(ValueError, match="no-such-codec"):
        mb.from_urdf(path)
